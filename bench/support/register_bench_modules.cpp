// Registers the benchmark-only modules in the process that links this file.
#include "support/bench_modules.hpp"

namespace chimera::bench {
CHIMERA_REGISTER_MODULE(BenchStamp);
CHIMERA_REGISTER_MODULE(BenchIdle);
CHIMERA_REGISTER_MODULE(BenchNullPid);
CHIMERA_REGISTER_MODULE(BenchStamper);
CHIMERA_REGISTER_MODULE(BenchStampCheck);
}  // namespace chimera::bench
