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

  // Hard tasks first: each must fit with those before it.
  for (const std::size_t i : order) {
    if (!cpu_tasks[i].hard) continue;
    set.critical[i] = true;
    const auto demand = demand_of(cpu_tasks[i], options);
    if (demand) {
      admitted.push_back(*demand);
      if (edf_test(admitted).outcome == EdfOutcome::kFeasible) continue;
      admitted.pop_back();  // judge the later hard tasks against a set that still holds
    }
    set.unfit_hard.push_back(i);
  }
  set.feasible = set.unfit_hard.empty();
  if (!set.feasible) return set;  // nothing more can be guaranteed on a CPU whose hard tasks do not fit

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

}  // namespace chimera::analysis
