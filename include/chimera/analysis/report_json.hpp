#pragma once
// What `chimera analyze --json` prints: the results format_report() shows as text, as one JSON
// document for tools that check a file's schedulability (contract section 4). Built from the same
// structs as the text, so the two never disagree. docs/scheduling.md shows an example.

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/analysis/report.hpp"
#include "chimera/analysis/schedulability.hpp"
#include "chimera/analysis/task_model.hpp"

namespace chimera::analysis {

/// The document's "format_version": raised when a key changes meaning or goes away (new keys
/// can appear without it), so a consumer can refuse a document it does not understand.
inline constexpr int kAnalysisJsonFormatVersion = 1;

/// One configuration as analysed: what format_report() is given.
struct AnalysedConfiguration {
  ReportContext context;
  std::vector<TaskModel> tasks;
  ConfigurationResult result;  // analyse_configuration() of `tasks`
};

/// {"format": "chimera-analyze", "format_version": 1, "file", "feasible", "configurations": [{
/// "name", "scheduler", "feasible", "overhead_ns", "measured", "can_miss": [task], "cpus": [{"cpu",
/// "utilisation", "utilisation_complete", "test", "bound", "outcome", "feasible", "edf"?,
/// "critical_set"? (muf), "tasks": [{"name", "cpu", "placed", "criticality", "period_ns",
/// "deadline_ns", "wcet_ns", "wcet_source", "analysed_c_ns", "response_ns", "response_kind",
/// "verdict", "critical"? (muf), "reason"}]}]}]}, with every duration in integer nanoseconds
/// (null where there is none) and tasks in the text report's order. Ends in '\n'. Not real-time
/// safe.
[[nodiscard]] std::string analysis_json(std::string_view file, std::span<const AnalysedConfiguration> configurations);

}  // namespace chimera::analysis
