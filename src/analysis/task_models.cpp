#include "chimera/analysis/task_models.hpp"

#include <algorithm>

namespace chimera::analysis {
namespace {

// C for one cycle (for a server: one job) and where it came from.
std::pair<std::int64_t, WcetSource> execution_time(const TaskSpec& t, const WcetProfile* profile,
                                                   const WcetProfile* measured) {
  if (t.wcet_ns) return {*t.wcet_ns, WcetSource::kFile};
  if (profile != nullptr)
    if (const ProfileEntry* e = profile->find(t.name)) return {e->wcet_ns, WcetSource::kProfile};
  if (measured != nullptr)
    if (const ProfileEntry* e = measured->find(t.name)) return {e->wcet_ns, WcetSource::kMeasured};
  return {0, WcetSource::kUnknown};
}

}  // namespace

std::vector<TaskModel> task_models(const SubsystemSpec& spec, std::span<const std::string> task_names,
                                   const WcetProfile* profile, const WcetProfile* measured) {
  std::vector<TaskModel> models;
  for (std::size_t i = 0; i < spec.tasks.size(); ++i) {
    const TaskSpec& t = spec.tasks[i];
    if (std::find(task_names.begin(), task_names.end(), t.name) == task_names.end()) continue;
    TaskModel m;
    m.name = t.name;
    const auto [c, source] = execution_time(t, profile, measured);
    m.wcet_ns = c;
    m.wcet_source = source;
    m.period_ns = t.period_ns.value_or(0);
    m.deadline_ns = t.deadline_ns;
    m.hard = t.criticality == Criticality::kHard;
    m.cpu = t.cpu.value_or(-1);
    m.file_index = static_cast<int>(i);
    // When the file gains `priority:` and `server: { budget, period }`, they map here: the
    // priority to user_priority; a server gets server = true, its budget as wcet_ns, the C found
    // above (its longest job) as job_wcet_ns, and its period as period_ns and deadline_ns.
    models.push_back(std::move(m));
  }
  return models;
}

}  // namespace chimera::analysis
