#include "chimera/analysis/cpu_assignment.hpp"

#include <algorithm>
#include <numeric>

#include "chimera/analysis/response_time.hpp"
#include "chimera/analysis/schedulability.hpp"
#include "chimera/analysis/task_models.hpp"
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

// Fixed priorities: whether every task's response-time bound (Bini and Baruah) is within
// min(D, T). O(n log n), from sums per priority rank; tasks of one rank interfere both ways.
bool bounded_by_deadlines(std::span<const TaskModel> tasks, SchedulerKind scheduler, const AnalysisOptions& options) {
  const auto ranks = fixed_priority_ranks(tasks, scheduler);
  const int levels = ranks.empty() ? 0 : *std::max_element(ranks.begin(), ranks.end()) + 1;
  std::vector<double> u(static_cast<std::size_t>(levels) + 1, 0.0);  // per rank, then prefix sums
  std::vector<double> w(u.size(), 0.0);                              // sum C (1 - U) likewise
  std::vector<Demand> demands;
  demands.reserve(tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    demands.push_back(*demand_of(tasks[i], options));
    const double ui = static_cast<double>(demands[i].c_ns) / static_cast<double>(demands[i].t_ns);
    u[static_cast<std::size_t>(ranks[i]) + 1] += ui;
    w[static_cast<std::size_t>(ranks[i]) + 1] += static_cast<double>(demands[i].c_ns) * (1.0 - ui);
  }
  for (std::size_t r = 1; r < u.size(); ++r) {
    u[r] += u[r - 1];
    w[r] += w[r - 1];
  }
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const auto level = static_cast<std::size_t>(ranks[i]) + 1;  // ranks 0 .. ranks[i], less the task itself
    const Demand& d = demands[i];
    const double ui = static_cast<double>(d.c_ns) / static_cast<double>(d.t_ns);
    const double bound =
        response_time_upper_bound(d.c_ns, u[level] - ui, w[level] - static_cast<double>(d.c_ns) * (1.0 - ui));
    if (!(bound * (1.0 + 1e-9) <= static_cast<double>(std::min(d.d_ns, d.t_ns)))) return false;
  }
  return true;
}

// Whether `cpu` stays schedulable with `task` added. Sufficient tests first, since this runs for
// every task and CPU, on the density sum C / min(D, T): a set is no harder than the same set with
// every period and deadline cut to min(D, T). Where that keeps the priority order (rm with every
// D >= T, dm with every D <= T), Liu and Layland's bound on the density suffices; for edf,
// density <= 1; for muf the hard tasks' density <= 1, since soft tasks never make it infeasible.
// For rm and dm, the response-time bound of Bini and Baruah next. Near the limits the exact
// analysis decides.
bool fits(const Cpu& cpu, const TaskModel& task, SchedulerKind scheduler, const AnalysisOptions& options) {
  constexpr double kSafety = 1e-9;  // the sums are in floating point; the exact test settles the rest
  std::vector<TaskModel> with = cpu.known;
  with.push_back(task);
  double density = 0;
  double hard_density = 0;
  bool late = true;   // every D >= T
  bool early = true;  // every D <= T
  for (const auto& t : with) {
    const Demand d = *demand_of(t, options);
    const double share = static_cast<double>(d.c_ns) / static_cast<double>(std::min(d.d_ns, d.t_ns));
    density += share;
    if (t.hard) hard_density += share;
    late = late && d.d_ns >= d.t_ns;
    early = early && d.d_ns <= d.t_ns;
  }
  const double bound = liu_layland_bound(static_cast<int>(with.size())) - kSafety;
  switch (scheduler) {
    case SchedulerKind::kRm:
      if ((late && density <= bound) || bounded_by_deadlines(with, scheduler, options)) return true;
      break;
    case SchedulerKind::kDm:
      if ((early && density <= bound) || bounded_by_deadlines(with, scheduler, options)) return true;
      break;
    case SchedulerKind::kEdf:
      if (density <= 1.0 - kSafety) return true;
      break;
    case SchedulerKind::kMuf:
      if (hard_density <= 1.0 - kSafety) return true;
      break;
  }
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

std::vector<int> assign_subsystem_cpus(const SubsystemSpec& spec, std::span<const int> cpus,
                                       const AnalysisOptions& options) {
  std::vector<std::string> names;
  names.reserve(spec.tasks.size());
  for (const auto& t : spec.tasks) names.push_back(t.name);
  return assign_cpus(task_models(spec, names), cpus, spec.scheduler, options);  // file order, one per task
}

std::vector<int> allowed_cpus(const SubsystemSpec& spec, int online_cpus) {
  if (!spec.cpus.empty()) return spec.cpus;
  std::vector<int> all(static_cast<std::size_t>(std::max(online_cpus, 1)));
  std::iota(all.begin(), all.end(), 0);
  return all;
}

}  // namespace chimera::analysis
