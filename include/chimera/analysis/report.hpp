#pragma once
// What `chimera analyze` prints for one configuration: per CPU its tasks (and how each got
// there), utilisation, bound, the test that decided, each task's C (and where it came from), T,
// D, response time or the reason it can miss; then one verdict line. docs/scheduling.md shows
// how to read it.

#include <span>
#include <string>

#include "chimera/analysis/schedulability.hpp"
#include "chimera/analysis/task_model.hpp"
#include "chimera/config/subsystem.hpp"

namespace chimera::analysis {

struct ReportContext {
  std::string file;           // the subsystem file, first word of the heading
  std::string configuration;  // its name
  SchedulerKind scheduler = SchedulerKind::kRm;
  AnalysisOptions options;
  /// How measured C were obtained (one line), or "" when no task's C was measured.
  std::string measured_note;
};

/// Lines ending in '\n'. `result` is analyse_configuration() of `tasks`. Not real-time safe.
[[nodiscard]] std::string format_report(const ReportContext& context, std::span<const TaskModel> tasks,
                                        const ConfigurationResult& result);

/// The names of the tasks that can miss (Verdict::kCanMiss), in file order.
[[nodiscard]] std::vector<std::string> tasks_that_can_miss(std::span<const TaskModel> tasks,
                                                           const ConfigurationResult& result);

}  // namespace chimera::analysis
