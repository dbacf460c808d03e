#pragma once
// The virtual clock: the same schedule as the real executive, run on simulated time by the
// calling thread, deterministically and as fast as the machine allows. Releases are at whole
// multiples of each period since the subsystem's start; a cycle takes no simulated time; jobs
// released at one instant run in the order (period, data-flow rank, position in the file).

#include <cstdint>
#include <vector>

#include "chimera/exec/task.hpp"
#include "release_order.hpp"

namespace chimera {

class VirtualExecutive {
 public:
  VirtualExecutive(std::vector<Task*> tasks, const ReleaseOrder& order);

  [[nodiscard]] std::int64_t now_ns() const { return now_ns_; }
  /// Applies a signal at the current simulated time.
  Result<void> signal(std::size_t task, Signal signal);
  /// Runs every release before `end_ns`, then sets the time to `end_ns`.
  void run_until(std::int64_t end_ns);

 private:
  std::vector<Task*> tasks_;
  std::vector<std::int64_t> next_release_;   // per task; < 0 when not scheduled
  std::vector<std::size_t> dispatch_order_;  // tasks sorted by (period, rank, index)
  std::int64_t now_ns_ = 0;
};

}  // namespace chimera
