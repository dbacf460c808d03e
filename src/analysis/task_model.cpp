#include "chimera/analysis/task_model.hpp"

namespace chimera::analysis {

std::string_view wcet_source_name(WcetSource source) {
  switch (source) {
    case WcetSource::kUnknown: return "unknown";
    case WcetSource::kFile: return "file";
    case WcetSource::kProfile: return "profile";
    case WcetSource::kMeasured: return "measured";
    case WcetSource::kVirtual: return "virtual_exec";
    case WcetSource::kSimulated: return "simulated";
  }
  return "?";
}

TaskModel as_the_run_knows(const TaskModel& task) {
  if (!task.run_wcet_ns) return task;
  TaskModel known = task;
  if (task.server) {
    known.job_wcet_ns = *task.run_wcet_ns;  // the budget is the file's either way
  } else {
    known.wcet_ns = *task.run_wcet_ns;
  }
  // wcet: or virtual_exec:, which the critical set does not tell apart.
  known.wcet_source = *task.run_wcet_ns > 0 ? WcetSource::kFile : WcetSource::kUnknown;
  return known;
}

std::optional<Demand> demand_of(const TaskModel& task, const AnalysisOptions& options) {
  if (is_background(task) || !wcet_known(task)) return std::nullopt;
  const std::int64_t overrun = task.server ? task.job_wcet_ns : 0;
  return Demand{task.wcet_ns + overrun + options.overhead_ns, task.period_ns, relative_deadline(task),
                task.release_jitter_ns};
}

}  // namespace chimera::analysis
