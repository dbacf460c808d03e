#pragma once
// Maximum-urgency-first's critical set (Stewart and Khosla 1991): the tasks of one CPU that the
// scheduler guarantees. Urgency is, in order: critical or not, then the dynamic priority, then
// the user priority, then first come first served; a critical task always beats a non-critical
// one, so the critical tasks run as if alone, by deadline among themselves.

#include <cstddef>
#include <span>
#include <vector>

#include "chimera/analysis/task_model.hpp"

namespace chimera::analysis {

struct CriticalSet {
  /// Per task given, in the same order: whether it is in the critical set. Every hard task with
  /// a period is, whether it fits or not (it must be guaranteed or the configuration refused).
  std::vector<bool> critical;
  /// Hard tasks that cannot be guaranteed, in the order they were admitted (shortest period
  /// first): their C is unknown, or with them the critical set fails the EDF test.
  std::vector<std::size_t> unfit_hard;
  /// Every hard task fits: the configuration is feasible under MUF on this CPU.
  bool feasible = true;
};

/// The order tasks are considered for the critical set: shortest period first, then shortest
/// relative deadline, higher user priority, then file order. Background tasks are left out.
[[nodiscard]] std::vector<std::size_t> muf_admission_order(std::span<const TaskModel> cpu_tasks);

/// The critical set of one CPU's tasks: first the hard tasks, each admitted if the critical set
/// stays feasible by EDF (utilisation <= 100% when every D >= T, the processor-demand test
/// otherwise); then the others in admission order while it stays feasible: the first that would
/// not fit, or whose C is unknown, ends the set. Background tasks are never critical. C includes
/// options.overhead_ns. Not real-time safe (allocates).
[[nodiscard]] CriticalSet muf_critical_set(std::span<const TaskModel> cpu_tasks, const AnalysisOptions& options = {});

}  // namespace chimera::analysis
