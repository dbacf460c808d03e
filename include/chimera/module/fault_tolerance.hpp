#pragma once
// For a module's error(): how a module that can live with an occasional late cycle (a controller
// of a simulated arm, a display) recovers from the timing faults the framework detects, while a
// run of them, or any method failure, still sends its task to ERROR.
//
//   Status error() override { return timing_.judge(*timing_of_cycle_); }   // timing_ = {50}

#include <cstdint>

#include "chimera/core/result.hpp"
#include "chimera/module/module.hpp"

namespace chimera {

class TimingFaultTolerance {
 public:
  /// Recovers from timing faults unless `limit` of them come in consecutive cycles.
  explicit TimingFaultTolerance(std::uint64_t limit) : limit_(limit) {}

  /// The verdict of error() for the fault `timing` describes. Real-time safe.
  Status judge(const CycleTiming& timing) noexcept {
    if (timing.fault != Fault::kDeadlineMissed && timing.fault != Fault::kBudgetOverrun)
      return Status::fail("not a timing fault: the method's failure stands");
    run_ = (seen_ && timing.cycle <= last_cycle_ + 1) ? run_ + 1 : 1;
    seen_ = true;
    last_cycle_ = timing.cycle;
    if (run_ >= limit_) return Status::fail("too many late cycles in a row");
    return Status::ok();
  }

 private:
  std::uint64_t limit_;
  std::uint64_t run_ = 0;
  std::uint64_t last_cycle_ = 0;
  bool seen_ = false;
};

}  // namespace chimera
