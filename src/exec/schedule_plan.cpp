#include "schedule_plan.hpp"

#include <unistd.h>

#include <algorithm>
#include <numeric>

#include "chimera/analysis/cpu_assignment.hpp"
#include "chimera/analysis/muf.hpp"
#include "chimera/analysis/task_models.hpp"

namespace chimera {

std::vector<int> subsystem_cpus(const SubsystemSpec& spec) {
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  return analysis::allowed_cpus(spec, static_cast<int>(std::max(1L, n)));
}

SchedulePlan make_schedule_plan(const ResolvedSubsystem& subsystem, const analysis::ReleaseOrder& order,
                                const std::vector<int>& cpus, const std::vector<std::string>& configuration) {
  const SubsystemSpec& spec = *subsystem.spec;
  SchedulePlan plan;
  plan.policy = spec.scheduler;
  // The same assignment `chimera analyze` shows: over every task of the file, so that a switch
  // never moves a task to another CPU.
  plan.cpu = analysis::assign_subsystem_cpus(spec, order, cpus);
  for (std::size_t i = 0; i < spec.tasks.size(); ++i) {
    const TaskSpec& t = spec.tasks[i];
    if (plan.cpu[i] < 0) plan.cpu[i] = cpus.empty() ? 0 : cpus.front();
    TaskUrgency u;
    u.background = !t.period_ns && !t.server;
    u.period_ns = t.period_ns ? *t.period_ns : (t.server ? t.server->period_ns : 0);
    u.deadline_ns = t.deadline_ns > 0 ? t.deadline_ns : u.period_ns;
    u.user_priority = t.priority;
    u.rank = order.rank[i];
    u.index = static_cast<int>(i);
    u.critical = t.criticality == Criticality::kHard;  // outside the configuration: as if alone
    plan.urgency.push_back(u);
  }
  if (plan.policy != SchedulerKind::kMuf) return plan;

  // MUF's critical set, per CPU, among the tasks of the configuration (analysis/muf.hpp).
  const auto models = analysis::task_models(spec, configuration, nullptr, nullptr, &order);
  for (const int cpu : cpus) {
    std::vector<analysis::TaskModel> on_cpu;
    for (const auto& m : models)
      if (plan.cpu[static_cast<std::size_t>(m.file_index)] == cpu) on_cpu.push_back(m);
    const analysis::CriticalSet set = analysis::runtime_critical_set(on_cpu);
    for (std::size_t j = 0; j < on_cpu.size(); ++j)
      plan.urgency[static_cast<std::size_t>(on_cpu[j].file_index)].critical = set.critical[j];
  }
  return plan;
}

}  // namespace chimera
