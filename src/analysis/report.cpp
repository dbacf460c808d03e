#include "chimera/analysis/report.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/core/duration_text.hpp"
#include "chimera/core/text_table.hpp"

namespace chimera::analysis {
namespace {

using Align = TextTable::Align;

std::string utilisation_text(const CpuResult& cpu) {
  return fmt::format("U = {}{:.3f}", cpu.utilisation_complete ? "" : "at least ", cpu.utilisation);
}

std::string edf_outcome_text(const EdfTest& edf) {
  if (edf.outcome == EdfOutcome::kFeasible) return "passes";
  return (edf.outcome == EdfOutcome::kGaveUp ? "cannot decide: " : "fails: ") + edf_failure_reason(edf);
}

// The EDF test of a set, as one clause: which form of the test, and its outcome.
std::string edf_test_text(const EdfTest& edf) {
  if (edf.outcome == EdfOutcome::kOverloaded) return edf_outcome_text(edf);
  if (edf.utilisation_decides) return "every D >= T, so U <= 1 decides: " + edf_outcome_text(edf);
  return fmt::format("some D < T: processor demand h(t) <= t checked up to L = {} (QPA, {} point{}): {}",
                     exact_duration_text(edf.bound_ns), edf.points, edf.points == 1 ? "" : "s", edf_outcome_text(edf));
}

// The line under a CPU's heading: utilisation, bound, and the test that decided.
std::string test_line(const CpuResult& cpu, std::span<const TaskModel> tasks) {
  switch (cpu.test) {
    case CpuTest::kNone: return cpu.tasks.empty() ? "no tasks" : "no task with a period";
    case CpuTest::kResponseTime: {
      std::string line = fmt::format("{}, Liu-Layland bound {:.3f} for {} task{}", utilisation_text(cpu), cpu.ll_bound,
                                     cpu.periodic, cpu.periodic == 1 ? "" : "s");
      if (!cpu.implicit_deadlines) return line + " (it holds only where D = T); response-time analysis decides";
      if (cpu.utilisation_complete && cpu.utilisation <= cpu.ll_bound)
        return line + ": under the bound, feasible; response times below";
      return line + ": above the bound; response-time analysis decides";
    }
    case CpuTest::kEdfUtilisation:
    case CpuTest::kEdfProcessorDemand:
      if (!cpu.utilisation_complete) return utilisation_text(cpu) + ", bound 1; some C unknown: EDF cannot decide";
      return fmt::format("{}, bound 1 (EDF); {}", utilisation_text(cpu), edf_test_text(cpu.edf));
    case CpuTest::kMufCriticalSet: {
      // The set the run orders jobs by, whether or not it passes the test with analysis' C.
      std::vector<std::string> critical;
      for (const auto& r : cpu.tasks)
        if (r.critical) critical.push_back(tasks[r.index].name);
      const std::string set =
          critical.empty() ? "critical set empty" : fmt::format("critical set {}", fmt::join(critical, ", "));
      const char* outcome = cpu.feasible        ? "every hard task fits"
                            : cpu.hard_left_out ? "a hard task does not fit"
                                                : "the critical set is not guaranteed";
      return fmt::format("{}; {}: U = {:.3f}, bound 1 (EDF among critical tasks); {}", utilisation_text(cpu), set,
                         cpu.edf.utilisation, outcome);
    }
  }
  return {};
}

std::string c_text(const TaskModel& t) {
  if (t.server)
    return fmt::format("{} + {}", t.wcet_ns > 0 ? exact_duration_text(t.wcet_ns) : "?",
                       t.job_wcet_ns > 0 ? exact_duration_text(t.job_wcet_ns) : "?");
  return t.wcet_ns > 0 ? exact_duration_text(t.wcet_ns) : "?";
}

std::string response_text(const TaskResult& r) {
  if (r.response_ns <= 0) return "-";
  return (r.response_is_bound ? "<= " : "") + exact_duration_text(r.response_ns);
}

std::string verdict_text(const TaskResult& r) {
  std::string text(verdict_name(r.verdict));
  if (r.critical && r.verdict == Verdict::kMeets) text += " (critical)";
  return r.reason.empty() ? text : text + ": " + r.reason;
}

std::string cpu_section(const CpuResult& cpu, std::span<const TaskModel> tasks) {
  std::string out = fmt::format("cpu {}: {}\n", cpu.cpu, test_line(cpu, tasks));
  if (cpu.tasks.empty()) return out;
  TextTable table({{"task", Align::kLeft},
                   {"placed", Align::kLeft},
                   {"crit", Align::kLeft},
                   {"C", Align::kRight},
                   {"from", Align::kLeft},
                   {"T", Align::kRight},
                   {"D", Align::kRight},
                   {"response", Align::kRight},
                   {"verdict", Align::kLeft}});
  for (const auto& r : cpu.tasks) {
    const TaskModel& t = tasks[r.index];
    const bool periodic = !is_background(t);
    table.add_row({t.name, t.cpu >= 0 ? "pinned" : "assigned", t.hard ? "hard" : "soft", c_text(t),
                   std::string(wcet_source_name(t.wcet_source)),
                   periodic ? exact_duration_text(t.period_ns) : "aperiodic",
                   periodic ? exact_duration_text(relative_deadline(t)) : "-", response_text(r), verdict_text(r)});
  }
  const std::string rendered = table.render();
  for (std::string_view rest = rendered; !rest.empty();) {
    const auto end = rest.find('\n');
    out += fmt::format("  {}\n", rest.substr(0, end));
    rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
  }
  return out;
}

std::string cpu_list(const ConfigurationResult& result) {
  std::vector<int> numbers;
  for (const auto& c : result.cpus) numbers.push_back(c.cpu);
  return fmt::format("{}", fmt::join(numbers, ", "));
}

}  // namespace

std::vector<std::string> tasks_that_can_miss(std::span<const TaskModel> tasks, const ConfigurationResult& result) {
  std::vector<std::size_t> missing;
  for (const auto& cpu : result.cpus)
    for (const auto& r : cpu.tasks)
      if (r.verdict == Verdict::kCanMiss) missing.push_back(r.index);
  std::sort(missing.begin(), missing.end());
  std::vector<std::string> names;
  names.reserve(missing.size());
  for (const std::size_t i : missing) names.push_back(tasks[i].name);
  return names;
}

std::string format_report(const ReportContext& context, std::span<const TaskModel> tasks,
                          const ConfigurationResult& result) {
  const std::string_view scheduler = scheduler_name(context.scheduler);
  std::string out = fmt::format(
      "{}: configuration '{}', {} task{} under {} on cpu{} {}; every C includes {} of "
      "framework overhead per cycle\n",
      context.file, context.configuration, tasks.size(), tasks.size() == 1 ? "" : "s", scheduler,
      result.cpus.size() == 1 ? "" : "s", cpu_list(result), exact_duration_text(context.options.overhead_ns));
  if (!context.measured_note.empty()) out += context.measured_note + "\n";
  for (const auto& cpu : result.cpus) out += cpu_section(cpu, tasks);

  if (result.feasible) {
    out += fmt::format("configuration '{}': feasible under {}\n", context.configuration, scheduler);
  } else {
    const auto missing = tasks_that_can_miss(tasks, result);
    out += fmt::format("configuration '{}': NOT feasible under {}: {} can miss\n", context.configuration, scheduler,
                       fmt::join(missing, ", "));
  }
  return out;
}

}  // namespace chimera::analysis
