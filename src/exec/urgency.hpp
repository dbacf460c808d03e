#pragma once
// The order in which each policy runs jobs (docs/scheduling.md): one comparison, used by the
// virtual executive to pick the next job on a CPU and by the real executive to turn that order
// into thread priorities, so that both clocks follow the same rule.
//
//   rm   period, then data-flow rank, then file order
//   dm   relative deadline, then period, rank, file order
//   edf  absolute deadline, then release (first come, first served), rank, file order
//   muf  critical set first, then absolute deadline (the dynamic priority), then the user
//        priority (higher first), then release (first come, first served), rank, file order
// Aperiodic tasks without a server come after every other task (background), first come first.

#include <cstdint>

#include "chimera/config/subsystem.hpp"

namespace chimera {

/// What a policy needs to know of a task; fixed for a configuration.
struct TaskUrgency {
  std::int64_t period_ns = 0;    // RM's key: the period, or a server's replenishment period
  std::int64_t deadline_ns = 0;  // DM's key: the relative deadline
  bool critical = true;          // MUF: a member of the critical set
  bool background = false;       // an aperiodic task without a server
  int user_priority = 0;         // MUF's third level: higher is more urgent
  int rank = 0;                  // data-flow rank among tasks of the same period
  int index = 0;                 // position in the file: the last tie-break
};

/// One job of a task.
struct JobUrgency {
  std::int64_t release_ns = 0;
  std::int64_t deadline_ns = 0;  // absolute
};

/// True if job `ja` of task `a` must run before job `jb` of task `b` under `policy`; a strict
/// order (false for a job compared with itself). Real-time safe.
bool more_urgent(SchedulerKind policy, const TaskUrgency& a, const JobUrgency& ja, const TaskUrgency& b,
                 const JobUrgency& jb) noexcept;

/// Whether the policy's order of two tasks never depends on their jobs (rm, dm): then fixed
/// thread priorities carry it out on the real clock.
constexpr bool is_fixed_priority(SchedulerKind policy) noexcept {
  return policy == SchedulerKind::kRm || policy == SchedulerKind::kDm;
}

}  // namespace chimera
