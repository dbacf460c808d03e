#include "chimera/analysis/report_json.hpp"

#include <algorithm>
#include <optional>

#include <nlohmann/json.hpp>

namespace chimera::analysis {
namespace {

// ordered_json keeps keys in the order written (name first, the details after) and tasks in the
// report's order, which is how people read the document when they look at it.
using Json = nlohmann::ordered_json;

Json ns_or_null(std::int64_t ns) { return ns > 0 ? Json(ns) : Json(nullptr); }

std::string_view test_name(CpuTest test) {
  switch (test) {
    case CpuTest::kNone: return "none";
    case CpuTest::kResponseTime: return "response_time";
    case CpuTest::kEdfUtilisation: return "edf_utilisation";
    case CpuTest::kEdfProcessorDemand: return "edf_processor_demand";
    case CpuTest::kMufCriticalSet: return "muf_critical_set";
  }
  return "?";
}

std::string_view edf_outcome_name(EdfOutcome outcome) {
  switch (outcome) {
    case EdfOutcome::kFeasible: return "feasible";
    case EdfOutcome::kOverloaded: return "overloaded";
    case EdfOutcome::kDemandExceeded: return "demand_exceeded";
    case EdfOutcome::kGaveUp: return "gave_up";
  }
  return "?";
}

// The bound the CPU's test compares U with: Liu and Layland's for fixed priorities (sufficient
// only), 1 for EDF and MUF's critical set; none when no task has a period.
Json bound_of(const CpuResult& cpu) {
  switch (cpu.test) {
    case CpuTest::kNone: return nullptr;
    case CpuTest::kResponseTime: return cpu.ll_bound;
    case CpuTest::kEdfUtilisation:
    case CpuTest::kEdfProcessorDemand:
    case CpuTest::kMufCriticalSet: return 1;
  }
  return nullptr;
}

// The outcome of the test that decided, in the words the text's heading line uses for it.
std::string_view outcome_of(const CpuResult& cpu) {
  switch (cpu.test) {
    case CpuTest::kNone: return "feasible";
    case CpuTest::kResponseTime:
      if (cpu.implicit_deadlines && cpu.utilisation_complete && cpu.utilisation <= cpu.ll_bound) return "under_bound";
      return cpu.feasible ? "response_times_meet" : "response_time_exceeds_deadline";
    case CpuTest::kEdfUtilisation:
    case CpuTest::kEdfProcessorDemand:
      // Some C unknown: the text says EDF cannot decide, and edf holds the test of the rest only.
      if (!cpu.utilisation_complete) return "execution_time_unknown";
      return edf_outcome_name(cpu.edf.outcome);
    case CpuTest::kMufCriticalSet:
      if (cpu.feasible) return "every_hard_task_fits";
      return cpu.hard_left_out ? "a_hard_task_does_not_fit" : "critical_set_not_guaranteed";
  }
  return "?";
}

Json edf_json(const EdfTest& edf) {
  Json out{{"outcome", edf_outcome_name(edf.outcome)},
           {"utilisation", edf.utilisation},
           {"utilisation_decides", edf.utilisation_decides}};
  if (!edf.utilisation_decides && edf.outcome != EdfOutcome::kOverloaded) {
    out["demand_bound_ns"] = ns_or_null(edf.bound_ns);
    out["points"] = edf.points;
  }
  if (edf.outcome == EdfOutcome::kDemandExceeded) {
    out["interval_ns"] = edf.interval_ns;
    out["demand_ns"] = edf.demand_ns;
  }
  return out;
}

std::string_view response_kind(const TaskResult& r) {
  if (r.response_ns <= 0) return "none";
  if (r.response_is_bound) return "upper_bound";
  return r.response_is_lower_bound ? "lower_bound" : "exact";
}

Json task_json(const TaskModel& t, const TaskResult& r, int cpu, bool muf) {
  const bool periodic = !is_background(t);
  Json out{{"name", t.name},
           {"cpu", cpu},
           {"placed", t.cpu >= 0 ? "pinned" : "assigned"},
           {"criticality", t.hard ? "hard" : "soft"},
           {"period_ns", periodic ? Json(t.period_ns) : Json(nullptr)},
           {"deadline_ns", periodic ? Json(relative_deadline(t)) : Json(nullptr)},
           {"wcet_ns", ns_or_null(t.wcet_ns)}};
  if (t.server) {
    out["server"] = true;
    out["job_wcet_ns"] = ns_or_null(t.job_wcet_ns);
  }
  out["wcet_source"] = wcet_source_name(t.wcet_source);
  // What the tests used: C with the overhead (and a server's one job), which response_ns is of.
  out["analysed_c_ns"] = r.demand ? Json(r.demand->c_ns) : Json(nullptr);
  out["response_ns"] = ns_or_null(r.response_ns);
  out["response_kind"] = response_kind(r);
  // The wait for same-rate producers on other CPUs that response_ns includes (0: none).
  out["release_jitter_ns"] = r.release_jitter_ns;
  out["verdict"] = verdict_name(r.verdict);
  if (muf) out["critical"] = r.critical;
  out["reason"] = r.reason;
  return out;
}

Json cpu_json(const CpuResult& cpu, std::span<const TaskModel> tasks) {
  const bool muf = cpu.test == CpuTest::kMufCriticalSet;
  Json out{{"cpu", cpu.cpu},
           {"utilisation", cpu.utilisation},
           {"utilisation_complete", cpu.utilisation_complete},
           {"periodic_tasks", cpu.periodic},
           {"test", test_name(cpu.test)},
           {"bound", bound_of(cpu)},
           {"outcome", outcome_of(cpu)},
           {"feasible", cpu.feasible}};
  if (cpu.test != CpuTest::kNone && cpu.test != CpuTest::kResponseTime) out["edf"] = edf_json(cpu.edf);
  if (muf) {
    // The set the text's heading names, the one the run uses, in admission order. A hard task
    // outside it (it does not fit) is listed apart, as the reason the CPU is infeasible.
    Json critical = Json::array();
    Json unfit = Json::array();
    for (const auto& r : cpu.tasks) {
      const TaskModel& t = tasks[r.index];
      if (r.critical)
        critical.push_back(t.name);
      else if (t.hard && !is_background(t))
        unfit.push_back(t.name);
    }
    out["critical_set"] = std::move(critical);
    out["unfit_hard"] = std::move(unfit);
  }
  Json rows = Json::array();
  for (const auto& r : cpu.tasks) rows.push_back(task_json(tasks[r.index], r, cpu.cpu, muf));
  out["tasks"] = std::move(rows);
  return out;
}

Json configuration_json(const AnalysedConfiguration& c) {
  Json cpus = Json::array();
  for (const auto& cpu : c.result.cpus) cpus.push_back(cpu_json(cpu, c.tasks));
  return Json{{"name", c.context.configuration},
              {"scheduler", scheduler_name(c.context.scheduler)},
              {"feasible", c.result.feasible},
              {"overhead_ns", c.context.options.overhead_ns},
              {"measured", c.context.measured_note.empty() ? Json(nullptr) : Json(c.context.measured_note)},
              {"can_miss", tasks_that_can_miss(c.tasks, c.result)},
              {"cpus", std::move(cpus)}};
}

}  // namespace

std::string analysis_json(std::string_view file, std::span<const AnalysedConfiguration> configurations) {
  Json list = Json::array();
  for (const auto& c : configurations) list.push_back(configuration_json(c));
  const bool feasible = std::all_of(configurations.begin(), configurations.end(),
                                    [](const AnalysedConfiguration& c) { return c.result.feasible; });
  const Json doc{{"format", "chimera-analyze"},
                 {"format_version", kAnalysisJsonFormatVersion},
                 {"file", file},
                 {"feasible", feasible},
                 {"configurations", std::move(list)}};
  return doc.dump(2) + "\n";
}

}  // namespace chimera::analysis
