#include "chimera/analysis/cpu_assignment.hpp"

#include <algorithm>
#include <map>
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

// Whether `cpu` stays schedulable with `added` placed on it. Sufficient tests first, since this
// runs for every task and CPU, on the density sum C / min(D, T): a set is no harder than the same
// set with every period and deadline cut to min(D, T). Where that keeps the priority order (rm with
// every D >= T, dm with every D <= T), Liu and Layland's bound on the density suffices; for edf,
// density <= 1; for muf the hard tasks' density <= 1, since soft tasks never make it infeasible.
// For rm and dm, the response-time bound of Bini and Baruah next. Near the limits the exact
// analysis decides.
bool fits(const Cpu& cpu, std::span<const TaskModel> added, SchedulerKind scheduler, const AnalysisOptions& options) {
  constexpr double kSafety = 1e-9;  // the sums are in floating point; the exact test settles the rest
  std::vector<TaskModel> with = cpu.known;
  with.insert(with.end(), added.begin(), added.end());
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

// What assignment places together: the unpinned tasks of one same-rate chain (TaskModel::chain),
// or one task alone. A chain split over CPUs makes each consumer wait for its producer on the
// other CPU at every release, so a chain goes whole onto one CPU whenever it fits there.
struct Unit {
  std::vector<std::size_t> members;  // indices into the tasks, in file order
  bool known = true;                 // every member's C is known
  double share = 0;                  // the members' utilisation, where known
  std::int64_t period_ns = 0;        // the chain's period (0: background)
  int first = 0;                     // file index of the first member: the last tie-break
  int pinned_cpu = -1;               // the CPU a pinned task of the chain is on, if any
};

std::vector<Unit> units_of(std::span<const TaskModel> tasks, const AnalysisOptions& options) {
  std::map<int, int> pinned_cpu;  // chain -> the CPU of its first pinned task
  for (const auto& t : tasks)
    if (t.cpu >= 0 && t.chain >= 0) pinned_cpu.emplace(t.chain, t.cpu);
  std::vector<Unit> units;
  std::map<int, std::size_t> unit_of_chain;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const TaskModel& t = tasks[i];
    if (t.cpu >= 0) continue;
    std::size_t u = units.size();
    if (t.chain >= 0) {
      const auto [at, added] = unit_of_chain.emplace(t.chain, units.size());
      u = at->second;
      if (!added) {
        units[u].members.push_back(i);
        units[u].known = units[u].known && demand_of(t, options).has_value();
        units[u].share += share(t, options);
        continue;
      }
    }
    Unit unit;
    unit.members.push_back(i);
    unit.known = demand_of(t, options).has_value();
    unit.share = share(t, options);
    unit.period_ns = t.period_ns;
    unit.first = t.file_index;
    if (const auto p = pinned_cpu.find(t.chain); t.chain >= 0 && p != pinned_cpu.end()) unit.pinned_cpu = p->second;
    units.push_back(std::move(unit));
  }
  return units;
}

// One assignment in progress: the CPUs with what is on them so far, and each task's CPU.
class Placement {
 public:
  Placement(std::span<const TaskModel> tasks, std::span<const int> cpus, SchedulerKind scheduler,
            const AnalysisOptions& options)
      : tasks_(tasks), scheduler_(scheduler), options_(options), cpu_of_(tasks.size(), -1) {
    for (const int c : cpus) state_.push_back(Cpu{c, {}, 0.0, 0});
    std::sort(state_.begin(), state_.end(), [](const Cpu& a, const Cpu& b) { return a.number < b.number; });
  }

  [[nodiscard]] bool no_cpus() const { return state_.empty(); }
  [[nodiscard]] std::vector<int> result() && { return std::move(cpu_of_); }

  void place_pinned() {
    for (std::size_t i = 0; i < tasks_.size(); ++i) {
      if (tasks_[i].cpu < 0) continue;
      cpu_of_[i] = tasks_[i].cpu;
      if (Cpu* at = find(tasks_[i].cpu)) place(i, *at);
    }
  }

  // Worst fit: the least-loaded CPU on which the unit fits whole, the CPU of its pinned tasks
  // first. A chain that fits nowhere whole is split, task by task, largest first.
  void place_known(const Unit& unit) {
    std::vector<TaskModel> members;
    for (const std::size_t i : unit.members) members.push_back(tasks_[i]);
    const auto candidates = by_load(unit.pinned_cpu);
    const auto whole = std::find_if(candidates.begin(), candidates.end(),
                                    [&](const Cpu* c) { return fits(*c, members, scheduler_, options_); });
    if (whole != candidates.end()) {
      for (const std::size_t i : unit.members) place(i, **whole);
      return;
    }
    std::vector<std::size_t> split = unit.members;
    std::stable_sort(split.begin(), split.end(), [&](std::size_t a, std::size_t b) {
      return share(tasks_[a], options_) > share(tasks_[b], options_);
    });
    for (const std::size_t i : split) {
      const auto one = by_load(-1);
      const auto feasible = std::find_if(one.begin(), one.end(), [&](const Cpu* c) {
        return fits(*c, std::span<const TaskModel>(&tasks_[i], 1), scheduler_, options_);
      });
      place(i, feasible != one.end() ? **feasible : *one.front());
    }
  }

  // A unit of unknown share goes whole on the CPU of its pinned tasks, else on the one with the
  // fewest such tasks, then the lowest load, then the lower number.
  void place_unknown(const Unit& unit) {
    Cpu* target = find(unit.pinned_cpu);
    if (target == nullptr)
      target = &*std::min_element(state_.begin(), state_.end(), [](const Cpu& a, const Cpu& b) {
        if (a.unknown != b.unknown) return a.unknown < b.unknown;
        return a.load < b.load;  // min_element keeps the first (lower number) on a tie
      });
    for (const std::size_t i : unit.members) place(i, *target);
  }

 private:
  Cpu* find(int number) {
    const auto at = std::find_if(state_.begin(), state_.end(), [&](const Cpu& c) { return c.number == number; });
    return at == state_.end() ? nullptr : &*at;
  }

  void place(std::size_t i, Cpu& cpu) {
    cpu_of_[i] = cpu.number;
    if (demand_of(tasks_[i], options_)) {
      cpu.known.push_back(tasks_[i]);
      cpu.load += share(tasks_[i], options_);
    } else {
      ++cpu.unknown;
    }
  }

  // The CPUs from the least loaded (ties: lower number), `preferred` first.
  std::vector<Cpu*> by_load(int preferred) {
    std::vector<Cpu*> order;
    order.reserve(state_.size());
    for (auto& c : state_) order.push_back(&c);
    std::stable_sort(order.begin(), order.end(), [&](const Cpu* a, const Cpu* b) {
      if ((a->number == preferred) != (b->number == preferred)) return a->number == preferred;
      return a->load < b->load;
    });
    return order;
  }

  std::span<const TaskModel> tasks_;
  SchedulerKind scheduler_;
  const AnalysisOptions& options_;
  std::vector<Cpu> state_;
  std::vector<int> cpu_of_;
};

}  // namespace

std::vector<int> assign_cpus(std::span<const TaskModel> tasks, std::span<const int> cpus, SchedulerKind scheduler,
                             const AnalysisOptions& options) {
  Placement placement(tasks, cpus, scheduler, options);
  placement.place_pinned();
  if (placement.no_cpus()) return std::move(placement).result();

  std::vector<Unit> known;
  std::vector<Unit> unknown;
  for (auto& u : units_of(tasks, options)) (u.known ? known : unknown).push_back(std::move(u));
  // Worst fit decreasing by the unit's utilisation (ties: shorter period, then file order).
  std::stable_sort(known.begin(), known.end(), [](const Unit& a, const Unit& b) {
    if (a.share != b.share) return a.share > b.share;
    if (a.period_ns != b.period_ns) return a.period_ns < b.period_ns;
    return a.first < b.first;
  });
  for (const Unit& unit : known) placement.place_known(unit);
  // Then the units of unknown share: periodic before background, by period, then file order:
  // spread evenly, never all on one CPU.
  std::stable_sort(unknown.begin(), unknown.end(), [](const Unit& a, const Unit& b) {
    const bool ba = a.period_ns <= 0;
    const bool bb = b.period_ns <= 0;
    if (ba != bb) return bb;
    if (a.period_ns != b.period_ns) return a.period_ns < b.period_ns;
    return a.first < b.first;
  });
  for (const Unit& unit : unknown) placement.place_unknown(unit);
  return std::move(placement).result();
}

std::vector<int> assign_subsystem_cpus(const SubsystemSpec& spec, const ReleaseOrder& order, std::span<const int> cpus,
                                       const AnalysisOptions& options) {
  std::vector<std::string> names;
  names.reserve(spec.tasks.size());
  for (const auto& t : spec.tasks) names.push_back(t.name);
  // File order, one per task; with the chains of the whole file, whichever configuration they are in.
  return assign_cpus(task_models(spec, names, nullptr, nullptr, &order), cpus, spec.scheduler, options);
}

std::vector<int> allowed_cpus(const SubsystemSpec& spec, int online_cpus) {
  if (!spec.cpus.empty()) return spec.cpus;
  std::vector<int> all(static_cast<std::size_t>(std::max(online_cpus, 1)));
  std::iota(all.begin(), all.end(), 0);
  return all;
}

}  // namespace chimera::analysis
