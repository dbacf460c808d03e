// libchimera: every part of the runtime, linked whole (src/CMakeLists.txt). The parts carry the
// code; the library itself carries its identity: the version and the module ABI it was built with.

#include <fmt/format.h>

#include "chimera/module/version.hpp"
#include "chimera/module_abi.hpp"

namespace chimera {

std::string version_text() {
  return fmt::format("chimera {} (module ABI {:016x})", kChimeraVersion, kModuleAbiFingerprint);
}

}  // namespace chimera
