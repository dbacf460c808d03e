#include "chimera/analysis/task_models.hpp"

#include <algorithm>
#include <map>
#include <string_view>
#include <utility>

namespace chimera::analysis {
namespace {

// C for one cycle (for a server: one job) and where it came from.
std::pair<std::int64_t, WcetSource> execution_time(const TaskSpec& t, const WcetProfile* profile,
                                                   const WcetProfile* measured) {
  if (t.wcet_ns) return {*t.wcet_ns, WcetSource::kFile};
  if (profile != nullptr)
    if (const ProfileEntry* e = profile->find(t.name)) return {e->wcet_ns, WcetSource::kProfile};
  if (measured != nullptr)
    if (const ProfileEntry* e = measured->find(t.name)) {
      if (!e->simulated) return {e->wcet_ns, WcetSource::kMeasured};
      // Simulated time: exactly the file's virtual_exec when the module charged nothing more.
      return {e->wcet_ns, e->wcet_ns == t.virtual_exec_ns ? WcetSource::kVirtual : WcetSource::kSimulated};
    }
  if (t.virtual_exec_ns > 0) return {t.virtual_exec_ns, WcetSource::kVirtual};  // a simulated cost, last
  return {0, WcetSource::kUnknown};
}

}  // namespace

std::vector<TaskModel> task_models(const SubsystemSpec& spec, std::span<const std::string> task_names,
                                   const WcetProfile* profile, const WcetProfile* measured, const ReleaseOrder* order) {
  // Which tasks of the file are named: a set, so that ten thousand names cost no more than a sort.
  std::vector<std::string_view> named(task_names.begin(), task_names.end());
  std::sort(named.begin(), named.end());
  const auto is_named = [&](const std::string& name) { return std::binary_search(named.begin(), named.end(), name); };
  // A same-rate chain is kept on one CPU so that its hand-overs cost nothing; across module
  // processes a hand-over on one CPU costs two context switches every release, and on two CPUs
  // only the producer's job (the consumer spins for a producer that is running it): so each
  // process's part of a chain is a chain of its own, named by its first task in the file.
  std::map<std::pair<int, std::string_view>, int> chain_part;  // (chain, process) -> its first task
  if (order != nullptr)
    for (std::size_t i = 0; i < spec.tasks.size() && i < order->chain.size(); ++i)
      chain_part.emplace(std::pair<int, std::string_view>{order->chain[i], spec.tasks[i].process}, static_cast<int>(i));
  std::vector<TaskModel> models;
  for (std::size_t i = 0; i < spec.tasks.size(); ++i) {
    const TaskSpec& t = spec.tasks[i];
    if (!is_named(t.name)) continue;
    TaskModel m;
    m.name = t.name;
    const auto [c, source] = execution_time(t, profile, measured);
    m.wcet_ns = c;
    m.wcet_source = source;
    m.period_ns = t.period_ns.value_or(0);
    m.deadline_ns = t.deadline_ns;
    m.hard = t.criticality == Criticality::kHard;
    m.user_priority = t.priority;
    m.cpu = t.cpu.value_or(-1);
    m.file_index = static_cast<int>(i);
    m.run_wcet_ns = t.wcet_ns ? *t.wcet_ns : t.virtual_exec_ns;
    if (t.server) {
      // A served aperiodic task: its budget every server period, plus the one job that may run
      // over it (docs/scheduling.md); the C found above is that longest job.
      m.server = true;
      m.wcet_ns = t.server->budget_ns;
      m.job_wcet_ns = c;
      m.period_ns = t.server->period_ns;
    }
    if (order != nullptr && i < order->chain.size()) {
      m.chain = chain_part.at({order->chain[i], t.process});
      for (const int p : order->predecessors[i])
        if (is_named(spec.tasks[static_cast<std::size_t>(p)].name)) m.same_rate_producers.push_back(p);
    }
    // late: changes how a run treats the task, not what analysis assumes (a skipped release
    // only lightens the load); virtual_exec counts only where nothing better is known.
    models.push_back(std::move(m));
  }
  return models;
}

}  // namespace chimera::analysis
