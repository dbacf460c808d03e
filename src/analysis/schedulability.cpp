#include "chimera/analysis/schedulability.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "chimera/analysis/muf.hpp"
#include "chimera/analysis/response_time.hpp"
#include "chimera/analysis/utilisation.hpp"
#include "chimera/core/duration_text.hpp"

namespace chimera::analysis {
namespace {

constexpr std::string_view kBackgroundReason = "aperiodic without a server: runs when nothing else does";

std::string unknown_reason(const TaskModel& t) {
  if (t.server && t.wcet_ns > 0) return "execution time unknown: the longest job of the server (give the task a wcet)";
  return "execution time unknown (give the task a wcet, or use --wcet-from)";
}

CpuTest test_for(std::span<const TaskModel> tasks, SchedulerKind scheduler) {
  switch (scheduler) {
    case SchedulerKind::kRm:
    case SchedulerKind::kDm: return CpuTest::kResponseTime;
    case SchedulerKind::kMuf: return CpuTest::kMufCriticalSet;
    case SchedulerKind::kEdf: break;
  }
  const bool late_deadlines = std::all_of(tasks.begin(), tasks.end(), [](const TaskModel& t) {
    return is_background(t) || relative_deadline(t) >= t.period_ns;
  });
  return late_deadlines ? CpuTest::kEdfUtilisation : CpuTest::kEdfProcessorDemand;
}

// The fields every scheduler fills alike: the demands, the counts, the utilisation.
CpuResult start_result(std::span<const TaskModel> tasks, SchedulerKind scheduler, const AnalysisOptions& options,
                       std::vector<std::optional<Demand>>& demands) {
  CpuResult cpu;
  cpu.scheduler = scheduler;
  std::vector<Demand> known;
  for (const auto& t : tasks) {
    demands.push_back(demand_of(t, options));
    if (is_background(t)) continue;
    ++cpu.periodic;
    if (relative_deadline(t) != t.period_ns) cpu.implicit_deadlines = false;
    if (demands.back())
      known.push_back(*demands.back());
    else
      cpu.utilisation_complete = false;
  }
  cpu.utilisation = utilisation(known);
  cpu.ll_bound = liu_layland_bound(cpu.periodic);
  if (cpu.periodic > 0) cpu.test = test_for(tasks, scheduler);
  return cpu;
}

TaskResult background_result(std::size_t i) {
  TaskResult r;
  r.index = i;
  r.verdict = Verdict::kBackground;
  r.reason = kBackgroundReason;
  return r;
}

void add_background(std::span<const TaskModel> tasks, CpuResult& cpu) {
  for (std::size_t i = 0; i < tasks.size(); ++i)
    if (is_background(tasks[i])) cpu.tasks.push_back(background_result(i));
}

std::string rta_reason(const ResponseTime& rt, const Demand& d) {
  switch (rt.outcome) {
    case RtaOutcome::kMeets: return {};
    case RtaOutcome::kMisses:
      return fmt::format("response time {}{} > deadline {}", rt.exact ? "" : "at least ",
                         exact_duration_text(rt.response_ns), exact_duration_text(d.d_ns));
    case RtaOutcome::kOverloaded:
      return fmt::format("overloaded: it and the tasks at or above its priority need {:.3f} of the processor",
                         rt.level_utilisation);
    case RtaOutcome::kGaveUp: return "the busy period at its priority is too long to analyse";
  }
  return {};
}

void analyse_fixed_priority(std::span<const TaskModel> tasks, const std::vector<std::optional<Demand>>& demands,
                            CpuResult& cpu) {
  const auto ranks = fixed_priority_ranks(tasks, cpu.scheduler);
  for (const std::size_t i : fixed_priority_order(tasks, cpu.scheduler)) {
    TaskResult r;
    r.index = i;
    r.demand = demands[i];
    std::vector<Demand> interference;
    std::string unknown_above;
    for (std::size_t j = 0; j < tasks.size(); ++j) {
      if (j == i || ranks[j] < 0 || ranks[j] > ranks[i]) continue;
      if (demands[j])
        interference.push_back(*demands[j]);
      else if (unknown_above.empty())
        unknown_above = tasks[j].name;
    }
    if (!r.demand) {
      r.reason = unknown_reason(tasks[i]);
    } else if (!unknown_above.empty()) {
      r.reason =
          fmt::format("cannot be bounded: {}, at or above its priority, has an unknown execution time", unknown_above);
    } else {
      const ResponseTime rt = response_time(*r.demand, interference);
      if (rt.outcome == RtaOutcome::kMeets || rt.outcome == RtaOutcome::kMisses) r.response_ns = rt.response_ns;
      r.response_is_lower_bound = rt.outcome == RtaOutcome::kMisses && !rt.exact;
      r.verdict = rt.outcome == RtaOutcome::kMeets ? Verdict::kMeets : Verdict::kCanMiss;
      r.reason = rta_reason(rt, *r.demand);
    }
    cpu.tasks.push_back(std::move(r));
  }
}

// Deadline order, then file order: how EDF favours tasks released together.
std::vector<std::size_t> deadline_order(std::span<const TaskModel> tasks) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < tasks.size(); ++i)
    if (!is_background(tasks[i])) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (relative_deadline(tasks[a]) != relative_deadline(tasks[b]))
      return relative_deadline(tasks[a]) < relative_deadline(tasks[b]);
    return tasks[a].file_index < tasks[b].file_index;
  });
  return order;
}

void analyse_edf(std::span<const TaskModel> tasks, const std::vector<std::optional<Demand>>& demands, CpuResult& cpu) {
  const auto order = deadline_order(tasks);
  std::vector<Demand> known;
  std::string unknown;
  for (const std::size_t i : order) {
    if (demands[i])
      known.push_back(*demands[i]);
    else if (unknown.empty())
      unknown = tasks[i].name;
  }
  cpu.edf = edf_test(known);
  if (cpu.edf.outcome == EdfOutcome::kFeasible) cpu.busy_period_ns = longest_busy_period(known).value_or(0);
  for (const std::size_t i : order) {
    TaskResult r;
    r.index = i;
    r.demand = demands[i];
    if (!r.demand) {
      r.reason = unknown_reason(tasks[i]);
    } else if (!unknown.empty()) {
      r.reason = fmt::format("cannot be bounded: {} on this CPU has an unknown execution time", unknown);
    } else if (cpu.edf.outcome == EdfOutcome::kFeasible) {
      r.verdict = Verdict::kMeets;
      r.response_ns = r.demand->d_ns;
      r.response_is_bound = true;
    } else {
      // EDF gives no task a guarantee once the CPU fails its test: any job can be the one late.
      r.reason = edf_failure_reason(cpu.edf);
    }
    cpu.tasks.push_back(std::move(r));
  }
}

// MUF's critical set is chosen from C, T and D alone, as the runtime chooses it (it knows no
// jitter); waits for producers on other CPUs are then checked against the set that holds.
CriticalSet critical_set_without_jitter(std::span<const TaskModel> tasks, bool from_a_file,
                                        const AnalysisOptions& options) {
  std::vector<TaskModel> plain(tasks.begin(), tasks.end());
  for (auto& t : plain) t.release_jitter_ns = 0;
  return from_a_file ? runtime_critical_set(plain) : muf_critical_set(plain, options);
}

// Why a soft task is outside MUF's critical set.
std::string outside_reason(const CriticalSet& set, const TaskModel& t) {
  if (!set.unfit_hard.empty()) return "outside the critical set: a hard task does not fit, so no soft task is admitted";
  if (!set.unknown_hard.empty())
    return "outside the critical set: a hard task's execution time is not known before the run (give it a wcet), so "
           "no soft task is admitted";
  if (run_known_wcet(t) <= 0)
    return "outside the critical set: its execution time is not known before the run (give the task a wcet)";
  return "outside the critical set, which admits the shortest periods first while they fit";
}

// Why a hard task is outside MUF's critical set: with the C the run knows it does not fit.
std::string left_out_reason(const std::vector<Demand>& critical_demands, const std::optional<Demand>& demand) {
  if (demand) {
    std::vector<Demand> with = critical_demands;
    with.push_back(*demand);
    const std::string why = edf_failure_reason(edf_test(with));
    if (!why.empty()) return "hard, but does not fit in the critical set: with it, " + why;
  }
  return fmt::format(
      "hard, but does not fit in the critical set with the C a run knows (wcet: or virtual_exec:, {} "
      "of overhead)",
      exact_duration_text(kDefaultOverheadNs));
}

void analyse_muf(std::span<const TaskModel> tasks, const std::vector<std::optional<Demand>>& demands,
                 const AnalysisOptions& options, CpuResult& cpu) {
  // The critical set is the one the run builds, from the C it knows before it starts (wcet:,
  // virtual_exec:) and its overhead; analysis then checks that set with its own C (the profile's,
  // a measurement), so that the set it names is the one the executive orders jobs by
  // (analysis/muf.hpp). Models made by hand, which no run shares, are admitted as they are.
  const bool from_a_file =
      std::any_of(tasks.begin(), tasks.end(), [](const TaskModel& t) { return t.run_wcet_ns.has_value(); });
  const CriticalSet set = critical_set_without_jitter(tasks, from_a_file, options);
  const auto order = muf_admission_order(tasks);
  std::vector<Demand> critical_demands;
  std::string unknown;  // a critical task whose C analysis does not know either
  for (const std::size_t i : order) {
    if (set.critical[i] && demands[i]) critical_demands.push_back(*demands[i]);
    if (set.critical[i] && !demands[i] && unknown.empty()) unknown = tasks[i].name;
  }
  cpu.edf = edf_test(critical_demands);
  const bool holds = unknown.empty() && cpu.edf.outcome == EdfOutcome::kFeasible;
  if (holds) cpu.busy_period_ns = longest_busy_period(critical_demands).value_or(0);

  std::vector<TaskResult> critical;
  std::vector<TaskResult> others;
  for (const std::size_t i : order) {
    const TaskModel& t = tasks[i];
    TaskResult r;
    r.index = i;
    r.demand = demands[i];
    r.critical = set.critical[i];
    if (!r.critical) {
      cpu.hard_left_out = cpu.hard_left_out || t.hard;
      if (!t.hard) r.verdict = Verdict::kNoGuarantee;
      r.reason = t.hard ? left_out_reason(critical_demands, r.demand) : outside_reason(set, t);
    } else if (!r.demand) {
      r.reason = (t.hard ? "hard, " : "") + unknown_reason(t);
    } else if (!unknown.empty()) {
      r.reason = fmt::format("cannot be bounded: {} in the critical set has an unknown execution time", unknown);
    } else if (holds) {
      r.verdict = Verdict::kMeets;
      r.response_ns = r.demand->d_ns;
      r.response_is_bound = true;
    } else {
      r.reason = "the critical set fails its EDF test: " + edf_failure_reason(cpu.edf);
    }
    (r.critical ? critical : others).push_back(std::move(r));
  }
  for (auto& r : critical) cpu.tasks.push_back(std::move(r));
  for (auto& r : others) cpu.tasks.push_back(std::move(r));
  cpu.feasible = holds && !cpu.hard_left_out;
}

}  // namespace

std::string edf_failure_reason(const EdfTest& test) {
  switch (test.outcome) {
    case EdfOutcome::kFeasible: return {};
    case EdfOutcome::kOverloaded: return fmt::format("overloaded: U = {:.3f} > 1", test.utilisation);
    case EdfOutcome::kDemandExceeded:
      return fmt::format("the jobs due in the first {} need {}", exact_duration_text(test.interval_ns),
                         exact_duration_text(test.demand_ns));
    case EdfOutcome::kGaveUp: return "the interval the processor-demand test must check could not be bounded";
  }
  return {};
}

std::string_view verdict_name(Verdict verdict) {
  switch (verdict) {
    case Verdict::kMeets: return "meets";
    case Verdict::kCanMiss: return "CAN MISS";
    case Verdict::kNoGuarantee: return "no guarantee";
    case Verdict::kBackground: return "background";
  }
  return "?";
}

CpuResult analyse_cpu(std::span<const TaskModel> tasks, SchedulerKind scheduler, const AnalysisOptions& options) {
  std::vector<std::optional<Demand>> demands;
  CpuResult cpu = start_result(tasks, scheduler, options, demands);
  switch (scheduler) {
    case SchedulerKind::kRm:
    case SchedulerKind::kDm: analyse_fixed_priority(tasks, demands, cpu); break;
    case SchedulerKind::kEdf: analyse_edf(tasks, demands, cpu); break;
    case SchedulerKind::kMuf: analyse_muf(tasks, demands, options, cpu); break;
  }
  add_background(tasks, cpu);
  if (scheduler != SchedulerKind::kMuf)
    cpu.feasible = std::all_of(cpu.tasks.begin(), cpu.tasks.end(), [](const TaskResult& r) {
      return r.verdict == Verdict::kMeets || r.verdict == Verdict::kBackground;
    });
  return cpu;
}

namespace {

// Every CPU of the configuration analysed once, with the tasks' jitter as given.
ConfigurationResult analyse_cpus(std::span<const TaskModel> tasks, std::span<const int> cpu_of,
                                 std::span<const int> cpus, SchedulerKind scheduler, const AnalysisOptions& options) {
  ConfigurationResult result;
  result.cpu_of.assign(cpu_of.begin(), cpu_of.end());
  std::set<int> all(cpus.begin(), cpus.end());
  all.insert(cpu_of.begin(), cpu_of.end());
  for (const int cpu : all) {
    std::vector<TaskModel> mine;
    std::vector<std::size_t> global;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      if (cpu_of[i] != cpu) continue;
      mine.push_back(tasks[i]);
      global.push_back(i);
    }
    CpuResult r = analyse_cpu(mine, scheduler, options);
    r.cpu = cpu;
    for (auto& t : r.tasks) t.index = global[t.index];
    result.feasible = result.feasible && r.feasible;
    result.cpus.push_back(std::move(r));
  }
  return result;
}

// How long after its release a job of the task can end at worst, if bounded: the exact response
// time under rm and dm; under edf and muf (a bound D only), its jitter plus the CPU's longest busy
// period when that is shorter, since the CPU is busy from when the job is ready until it ends.
std::optional<std::int64_t> completion_bound(const ConfigurationResult& result, std::size_t task,
                                             std::int64_t jitter_ns) {
  for (const auto& cpu : result.cpus)
    for (const auto& r : cpu.tasks) {
      if (r.index != task) continue;
      if (r.verdict != Verdict::kMeets || r.response_ns <= 0) return std::nullopt;
      if (r.response_is_bound && cpu.busy_period_ns > 0) return std::min(r.response_ns, jitter_ns + cpu.busy_period_ns);
      return r.response_ns;
    }
  return std::nullopt;
}

// A task's waits for same-rate producers on other CPUs (the same-rate rule): the longest of their
// response times is how late after its release it may start, its release jitter. A producer
// without a bound (it can miss, or is promised nothing) leaves the task without one: the runtime
// would wait up to half its deadline for it, then run on the previous cycle's value.
struct CrossCpuWait {
  std::int64_t jitter_ns = 0;
  std::string longest;    // the producer it waits longest for
  std::string unbounded;  // a producer without a bound, if any
  std::string behind;     // the task of its thread that waits, when it is not the task itself
};

// Under rm and dm the periodic tasks of one CPU, one priority and one period share a thread that
// runs them one after the other in data-flow order (docs/scheduling.md), so a task that waits for
// a producer on another CPU holds up the others of its thread too. Each gets the worst wait of its
// thread: for those before the waiter in the order that is more than they wait, on the safe side.
void share_waits_within_threads(std::span<const TaskModel> tasks, std::span<const int> cpu_of, SchedulerKind scheduler,
                                std::vector<CrossCpuWait>& waits) {
  if (scheduler != SchedulerKind::kRm && scheduler != SchedulerKind::kDm) return;
  const auto worse = [&](std::size_t a, std::size_t b) {  // whether a's wait is worse than b's
    if (waits[a].unbounded.empty() != waits[b].unbounded.empty()) return !waits[a].unbounded.empty();
    return waits[a].jitter_ns > waits[b].jitter_ns;
  };
  std::map<std::tuple<int, std::int64_t, std::int64_t>, std::size_t> worst;  // thread -> its worst waiter
  const auto thread_of = [&](std::size_t i) {
    const std::int64_t level = scheduler == SchedulerKind::kRm ? tasks[i].period_ns : relative_deadline(tasks[i]);
    return std::tuple{cpu_of[i], level, tasks[i].period_ns};
  };
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (is_background(tasks[i]) || tasks[i].server) continue;
    const auto [at, added] = worst.emplace(thread_of(i), i);
    if (!added && worse(i, at->second)) at->second = i;
  }
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (is_background(tasks[i]) || tasks[i].server) continue;
    const std::size_t w = worst.at(thread_of(i));
    if (w == i || !worse(w, i)) continue;
    waits[i] = waits[w];
    waits[i].behind = tasks[w].name;
  }
}

CrossCpuWait cross_cpu_wait(std::span<const TaskModel> tasks, std::span<const int> cpu_of,
                            const std::vector<int>& position, std::size_t i, const ConfigurationResult& result) {
  CrossCpuWait wait;
  for (const int producer : tasks[i].same_rate_producers) {
    if (producer < 0 || static_cast<std::size_t>(producer) >= position.size()) continue;
    const int p = position[static_cast<std::size_t>(producer)];
    if (p < 0 || cpu_of[static_cast<std::size_t>(p)] == cpu_of[i]) continue;  // not in it, or one CPU
    const auto end =
        completion_bound(result, static_cast<std::size_t>(p), tasks[static_cast<std::size_t>(p)].release_jitter_ns);
    if (!end) {
      if (wait.unbounded.empty()) wait.unbounded = tasks[static_cast<std::size_t>(p)].name;
      continue;
    }
    if (*end > wait.jitter_ns) {
      wait.jitter_ns = *end;
      wait.longest = tasks[static_cast<std::size_t>(p)].name;
    }
  }
  return wait;
}

}  // namespace

namespace {

// What the waits do to one verdict: say how long a task that meets may wait, refuse a bound to a
// task that waits for an unbounded producer (or whose waits did not settle).
void apply_wait(const TaskModel& task, const CrossCpuWait& wait, std::int64_t jitter_ns, bool settled, TaskResult& r) {
  r.release_jitter_ns = jitter_ns;
  // A run waits at most half the deadline (release_policy::producer_wait_until), then goes on with
  // the producer's previous value: the time is kept, the same-rate order is not. Analysis counts
  // the whole wait, on the safe side, and says where the two part.
  if (r.verdict == Verdict::kCanMiss && jitter_ns > 0 && 2 * jitter_ns > relative_deadline(task) &&
      !wait.longest.empty())
    r.reason += fmt::format(
        "; it waits up to {} for {} on another CPU, past half its deadline, where a run stops waiting and "
        "reads {}'s previous value (an order timeout): keep the chain on one CPU",
        exact_duration_text(jitter_ns), wait.longest, wait.longest);
  if (r.verdict != Verdict::kMeets || (jitter_ns == 0 && wait.unbounded.empty())) return;
  if (!wait.unbounded.empty() || !settled) {
    r.verdict = Verdict::kCanMiss;
    r.response_ns = 0;
    r.response_is_bound = false;
    r.reason =
        !wait.unbounded.empty()
            ? fmt::format("cannot be bounded: {} for {} on another CPU, which has no bound",
                          wait.behind.empty() ? "it waits" : wait.behind + ", on its thread, waits", wait.unbounded)
            : std::string("cannot be bounded: the waits for producers on other CPUs did not settle");
  } else if (wait.behind.empty()) {
    r.reason =
        fmt::format("after waiting up to {} for {} on another CPU", exact_duration_text(jitter_ns), wait.longest);
  } else {
    r.reason = fmt::format("after waiting up to {} behind {}, on its thread, which waits for {} on another CPU",
                           exact_duration_text(jitter_ns), wait.behind, wait.longest);
  }
}

}  // namespace

ConfigurationResult analyse_configuration(std::span<const TaskModel> tasks, std::span<const int> cpu_of,
                                          std::span<const int> cpus, SchedulerKind scheduler,
                                          const AnalysisOptions& options) {
  // Position in `tasks` of each file index, to find a task's producers among them.
  int last = -1;
  for (const auto& t : tasks) last = std::max(last, t.file_index);
  std::vector<int> position(static_cast<std::size_t>(last + 1), -1);
  for (std::size_t i = 0; i < tasks.size(); ++i)
    position[static_cast<std::size_t>(tasks[i].file_index)] = static_cast<int>(i);

  // Holistic analysis (Tindell and Clark 1994): a consumer's jitter is its producers' response
  // time, which the consumer's own jitter can lengthen on their CPU in turn. Jitter only grows from
  // round to round and a response past the deadline ends it, so this settles; a bound on the rounds
  // keeps a pathological set from taking long.
  std::vector<TaskModel> jittered(tasks.begin(), tasks.end());
  for (auto& t : jittered) t.release_jitter_ns = 0;
  ConfigurationResult result = analyse_cpus(jittered, cpu_of, cpus, scheduler, options);
  std::vector<CrossCpuWait> waits(tasks.size());
  const std::size_t max_rounds = 2 * tasks.size() + 4;
  bool settled = false;
  for (std::size_t round = 0; round < max_rounds && !settled; ++round) {
    for (std::size_t i = 0; i < tasks.size(); ++i) waits[i] = cross_cpu_wait(jittered, cpu_of, position, i, result);
    share_waits_within_threads(jittered, cpu_of, scheduler, waits);
    settled = true;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      if (waits[i].jitter_ns <= jittered[i].release_jitter_ns) continue;
      jittered[i].release_jitter_ns = waits[i].jitter_ns;
      settled = false;
    }
    if (!settled) result = analyse_cpus(jittered, cpu_of, cpus, scheduler, options);
  }

  result.feasible = true;
  for (auto& cpu : result.cpus) {
    for (auto& r : cpu.tasks)
      apply_wait(tasks[r.index], waits[r.index], jittered[r.index].release_jitter_ns, settled, r);
    // A task that can miss makes its CPU infeasible; under muf only critical tasks can (the others
    // are promised nothing), so the rule is the same for every scheduler.
    cpu.feasible = cpu.feasible && std::none_of(cpu.tasks.begin(), cpu.tasks.end(),
                                                [](const TaskResult& r) { return r.verdict == Verdict::kCanMiss; });
    result.feasible = result.feasible && cpu.feasible;
  }
  return result;
}

}  // namespace chimera::analysis
