#include "chimera/analysis/schedulability.hpp"

#include <algorithm>
#include <set>

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
  const CriticalSet set = from_a_file ? runtime_critical_set(tasks) : muf_critical_set(tasks, options);
  const auto order = muf_admission_order(tasks);
  std::vector<Demand> critical_demands;
  std::string unknown;  // a critical task whose C analysis does not know either
  for (const std::size_t i : order) {
    if (set.critical[i] && demands[i]) critical_demands.push_back(*demands[i]);
    if (set.critical[i] && !demands[i] && unknown.empty()) unknown = tasks[i].name;
  }
  cpu.edf = edf_test(critical_demands);
  const bool holds = unknown.empty() && cpu.edf.outcome == EdfOutcome::kFeasible;

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

ConfigurationResult analyse_configuration(std::span<const TaskModel> tasks, std::span<const int> cpu_of,
                                          std::span<const int> cpus, SchedulerKind scheduler,
                                          const AnalysisOptions& options) {
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

}  // namespace chimera::analysis
