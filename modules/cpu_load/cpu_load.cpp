// cpu_load: a task that only takes time. For what-if studies and schedulability experiments on
// either clock, for benchmarks (many trivial tasks), and for injecting timing failures.

#include "module_docs/cpu_load.hpp"

#include <cmath>
#include <cstdint>
#include <ctime>

#include "chimera/module/registry.hpp"

namespace chimera::modules {
namespace {

std::int64_t ns_of(double seconds) { return static_cast<std::int64_t>(std::llround(seconds * 1e9)); }

std::int64_t thread_cpu_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

class CpuLoad final : public Module {
 public:
  static constexpr const char* kName = "cpu_load";
  static constexpr const char* kSummary = docs::cpu_load::kSummary;
  static constexpr const char* kDoc = docs::cpu_load::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.param("exec", 0.0, "s", "execution time of each cycle").at_least(0);
    d.param("overrun_every", 0.0, "cycles", "every this many cycles one lasts longer (0: never)").whole().at_least(0);
    d.param("overrun", 0.0, "s", "how much longer that cycle lasts").at_least(0);
    d.param("recover", false, "", "error() recovers from timing failures");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    const double exec = p.number("exec");
    const double every = p.number("overrun_every");
    const double overrun = p.number("overrun");
    if (!(exec >= 0.0) || !(overrun >= 0.0)) return Status::fail("cpu_load: exec and overrun must be >= 0 s");
    if (!(every >= 0.0) || every != std::floor(every))
      return Status::fail("cpu_load: overrun_every must be a whole number of cycles >= 0");
    exec_ns_ = ns_of(exec);
    overrun_ns_ = ns_of(overrun);
    every_ = static_cast<std::uint64_t>(every);
    recover_ = p.flag("recover");
    timing_ = &ctx.timing();
    return Status::ok();
  }

  Status cycle() override {
    ++cycles_;
    const std::int64_t t = exec_ns_ + (every_ != 0 && cycles_ % every_ == 0 ? overrun_ns_ : 0);
    if (timing_->virtual_clock) {
      consume_virtual_time(t);
    } else {
      // Spin on the thread's own CPU clock: the load is `t` of CPU however often it is preempted.
      const std::int64_t until = thread_cpu_ns() + t;
      while (thread_cpu_ns() < until) {
      }
    }
    return Status::ok();
  }

  Status error() override {
    const bool timing = timing_->fault == Fault::kDeadlineMissed || timing_->fault == Fault::kBudgetOverrun;
    return recover_ && timing ? Status::ok() : Status::fail("cpu_load: a timing failure, not recovered");
  }

 private:
  const CycleTiming* timing_ = nullptr;
  std::int64_t exec_ns_ = 0;
  std::int64_t overrun_ns_ = 0;
  std::uint64_t every_ = 0;
  std::uint64_t cycles_ = 0;
  bool recover_ = false;
};

CHIMERA_REGISTER_MODULE(CpuLoad);

}  // namespace
}  // namespace chimera::modules
