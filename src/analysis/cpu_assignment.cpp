#include "chimera/analysis/cpu_assignment.hpp"

#include <algorithm>
#include <numeric>

#include "chimera/analysis/schedulability.hpp"
#include "chimera/analysis/utilisation.hpp"

namespace chimera::analysis {
namespace {

struct Cpu {
  int number = 0;
  std::vector<TaskModel> known;  // tasks of known C placed here so far
  double load = 0;               // their utilisation
  int unknown = 0;               // tasks of unknown share placed here
};

double share(const TaskModel& t, const AnalysisOptions& options) {
  const auto d = demand_of(t, options);
  return d ? static_cast<double>(d->c_ns) / static_cast<double>(d->t_ns) : 0.0;
}

// Whether `cpu` stays schedulable with `task` added. The sufficient tests first, since this runs
// for every task and CPU: Liu and Layland under rm or dm with D = T, U <= 1 under edf with D >= T.
bool fits(const Cpu& cpu, const TaskModel& task, SchedulerKind scheduler, const AnalysisOptions& options) {
  std::vector<TaskModel> with = cpu.known;
  with.push_back(task);
  std::vector<Demand> demands;
  bool implicit = true;
  bool late = true;
  for (const auto& t : with) {
    demands.push_back(*demand_of(t, options));
    implicit = implicit && relative_deadline(t) == t.period_ns;
    late = late && relative_deadline(t) >= t.period_ns;
  }
  if ((scheduler == SchedulerKind::kRm || scheduler == SchedulerKind::kDm) && implicit &&
      utilisation(demands) <= liu_layland_bound(static_cast<int>(demands.size())))
    return true;
  if (scheduler == SchedulerKind::kEdf && late) return utilisation_at_most_one(demands);
  return analyse_cpu(with, scheduler, options).feasible;
}

}  // namespace

std::vector<int> assign_cpus(std::span<const TaskModel> tasks, std::span<const int> cpus, SchedulerKind scheduler,
                             const AnalysisOptions& options) {
  std::vector<int> cpu_of(tasks.size(), -1);
  std::vector<Cpu> state;
  for (const int c : cpus) state.push_back(Cpu{c, {}, 0.0, 0});
  std::sort(state.begin(), state.end(), [](const Cpu& a, const Cpu& b) { return a.number < b.number; });
  const auto find = [&](int number) {
    return std::find_if(state.begin(), state.end(), [&](const Cpu& c) { return c.number == number; });
  };
  const auto place = [&](std::size_t i, Cpu& cpu) {
    cpu_of[i] = cpu.number;
    if (demand_of(tasks[i], options)) {
      cpu.known.push_back(tasks[i]);
      cpu.load += share(tasks[i], options);
    } else {
      ++cpu.unknown;
    }
  };

  std::vector<std::size_t> known;
  std::vector<std::size_t> unknown;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (tasks[i].cpu >= 0) {
      cpu_of[i] = tasks[i].cpu;
      if (auto at = find(tasks[i].cpu); at != state.end()) place(i, *at);
    } else {
      (demand_of(tasks[i], options) ? known : unknown).push_back(i);
    }
  }
  if (state.empty()) return cpu_of;

  std::sort(known.begin(), known.end(), [&](std::size_t a, std::size_t b) {
    const double ua = share(tasks[a], options);
    const double ub = share(tasks[b], options);
    if (ua != ub) return ua > ub;
    if (tasks[a].period_ns != tasks[b].period_ns) return tasks[a].period_ns < tasks[b].period_ns;
    return tasks[a].file_index < tasks[b].file_index;
  });
  for (const std::size_t i : known) {
    std::vector<Cpu*> by_load;
    by_load.reserve(state.size());
    for (auto& c : state) by_load.push_back(&c);
    std::stable_sort(by_load.begin(), by_load.end(), [](const Cpu* a, const Cpu* b) { return a->load < b->load; });
    const auto feasible = std::find_if(by_load.begin(), by_load.end(),
                                       [&](const Cpu* c) { return fits(*c, tasks[i], scheduler, options); });
    place(i, feasible != by_load.end() ? **feasible : *by_load.front());
  }

  // Periodic tasks before background ones, each group by period, then file order.
  std::sort(unknown.begin(), unknown.end(), [&](std::size_t a, std::size_t b) {
    const bool ba = is_background(tasks[a]);
    const bool bb = is_background(tasks[b]);
    if (ba != bb) return bb;
    if (tasks[a].period_ns != tasks[b].period_ns) return tasks[a].period_ns < tasks[b].period_ns;
    return tasks[a].file_index < tasks[b].file_index;
  });
  for (const std::size_t i : unknown) {
    const auto least = std::min_element(state.begin(), state.end(), [](const Cpu& a, const Cpu& b) {
      if (a.unknown != b.unknown) return a.unknown < b.unknown;
      return a.load < b.load;  // min_element keeps the first (lower number) on a tie
    });
    place(i, *least);
  }
  return cpu_of;
}

std::vector<int> allowed_cpus(const SubsystemSpec& spec, int online_cpus) {
  if (!spec.cpus.empty()) return spec.cpus;
  std::vector<int> all(static_cast<std::size_t>(std::max(online_cpus, 1)));
  std::iota(all.begin(), all.end(), 0);
  return all;
}

}  // namespace chimera::analysis
