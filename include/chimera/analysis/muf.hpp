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
  /// Per task given, in the same order: whether it is in the critical set. A task outside it is
  /// not critical, hard or not: a hard task that does not fit is left out (so that it cannot
  /// take the time of those that do fit).
  std::vector<bool> critical;
  /// Hard tasks whose C is known and with which the critical set would fail the EDF test, in the
  /// order they were considered (shortest period first). Not critical.
  std::vector<std::size_t> unfit_hard;
  /// Hard tasks whose C is unknown: critical (hard tasks are, unless known not to fit) but
  /// unchecked, so nothing on the CPU can be guaranteed by this set alone.
  std::vector<std::size_t> unknown_hard;
  /// Every hard task is critical and checked: the configuration is feasible under MUF on this CPU.
  bool feasible = true;
};

/// The order tasks are considered for the critical set: shortest period first, then shortest
/// relative deadline, higher user priority, then file order. Background tasks are left out.
[[nodiscard]] std::vector<std::size_t> muf_admission_order(std::span<const TaskModel> cpu_tasks);

/// The critical set of one CPU's tasks. First the hard tasks in admission order: one of known C
/// is admitted if the set stays feasible by EDF (utilisation <= 100% when every D >= T, the
/// processor-demand test otherwise), else it is unfit and left out, and the later ones are judged
/// against the set that holds; one of unknown C is admitted unchecked. Then, only when every hard
/// task was admitted and checked, the soft tasks in admission order while the set stays feasible:
/// the first that would not fit, or whose C is unknown, ends the set. Once a hard task is unfit
/// or unchecked no soft task is admitted, so that the unfit hard task competes with the soft ones
/// by deadline instead of running below them. Background tasks are never critical. C includes
/// options.overhead_ns. Not real-time safe (allocates).
[[nodiscard]] CriticalSet muf_critical_set(std::span<const TaskModel> cpu_tasks, const AnalysisOptions& options = {});

/// The critical set a run uses: muf_critical_set() over the C a run knows before it starts
/// (TaskModel::run_wcet_ns: the file's `wcet:`, else its `virtual_exec:`) and the default
/// overhead. The executive orders jobs by it and `chimera analyze` checks it with its own C
/// (profile, measurement), so that both name the same critical set. Not real-time safe.
[[nodiscard]] CriticalSet runtime_critical_set(std::span<const TaskModel> cpu_tasks);

}  // namespace chimera::analysis
