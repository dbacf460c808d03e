#include "chimera/analysis/muf.hpp"

#include <algorithm>

#include "chimera/analysis/processor_demand.hpp"

namespace chimera::analysis {

std::vector<std::size_t> muf_admission_order(std::span<const TaskModel> cpu_tasks) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < cpu_tasks.size(); ++i)
    if (!is_background(cpu_tasks[i])) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const TaskModel& x = cpu_tasks[a];
    const TaskModel& y = cpu_tasks[b];
    if (x.period_ns != y.period_ns) return x.period_ns < y.period_ns;
    if (relative_deadline(x) != relative_deadline(y)) return relative_deadline(x) < relative_deadline(y);
    if (x.user_priority != y.user_priority) return x.user_priority > y.user_priority;
    return x.file_index < y.file_index;
  });
  return order;
}

CriticalSet muf_critical_set(std::span<const TaskModel> cpu_tasks, const AnalysisOptions& options) {
  CriticalSet set;
  set.critical.assign(cpu_tasks.size(), false);
  const auto order = muf_admission_order(cpu_tasks);
  std::vector<Demand> admitted;

  // Hard tasks first: each must fit with those before it; one that does not is left out, and the
  // later ones are judged against the set that still holds.
  for (const std::size_t i : order) {
    if (!cpu_tasks[i].hard) continue;
    const auto demand = demand_of(cpu_tasks[i], options);
    if (!demand) {
      set.critical[i] = true;  // hard and unchecked: nothing says it does not fit
      set.unknown_hard.push_back(i);
      continue;
    }
    admitted.push_back(*demand);
    if (edf_test(admitted).outcome == EdfOutcome::kFeasible) {
      set.critical[i] = true;
      continue;
    }
    admitted.pop_back();
    set.unfit_hard.push_back(i);
  }
  set.feasible = set.unfit_hard.empty() && set.unknown_hard.empty();
  // A soft task admitted now would outrank a hard one left out, or take time a hard one of
  // unknown C may need: none is.
  if (!set.feasible) return set;

  // Then the others, shortest period first, while the load stays feasible.
  for (const std::size_t i : order) {
    if (cpu_tasks[i].hard) continue;
    const auto demand = demand_of(cpu_tasks[i], options);
    if (!demand) break;
    admitted.push_back(*demand);
    if (edf_test(admitted).outcome != EdfOutcome::kFeasible) break;
    set.critical[i] = true;
  }
  return set;
}

CriticalSet runtime_critical_set(std::span<const TaskModel> cpu_tasks) {
  std::vector<TaskModel> known;
  known.reserve(cpu_tasks.size());
  for (const TaskModel& t : cpu_tasks) known.push_back(as_the_run_knows(t));
  return muf_critical_set(known, AnalysisOptions{});
}

}  // namespace chimera::analysis
