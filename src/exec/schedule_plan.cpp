#include "schedule_plan.hpp"

#include <unistd.h>

#include <algorithm>
#include <numeric>

namespace chimera {

namespace {

// Utilisation of a task as a fraction, 0 when its cost is unknown or it is background work.
double utilisation(const TaskSpec& t) {
  const std::int64_t cost = planned_cost_ns(t);
  const std::int64_t period = t.period_ns ? *t.period_ns : (t.server ? t.server->period_ns : 0);
  if (t.server) return static_cast<double>(t.server->budget_ns) / static_cast<double>(t.server->period_ns);
  if (period <= 0 || cost <= 0) return 0.0;
  return static_cast<double>(cost) / static_cast<double>(period);
}

// Worst-fit decreasing: the heaviest task first, each onto the least loaded CPU (ties: fewer
// tasks, then the lower CPU). Balancing leaves slack on every CPU, and tasks of unknown cost
// still spread evenly instead of piling onto the first CPU.
std::vector<int> assign(const std::vector<const TaskSpec*>& tasks, const std::vector<int>& cpus) {
  std::vector<int> out(tasks.size(), cpus.empty() ? 0 : cpus.front());
  std::vector<double> load(cpus.size(), 0.0);
  std::vector<int> count(cpus.size(), 0);
  auto slot_of = [&](int cpu) {
    const auto it = std::find(cpus.begin(), cpus.end(), cpu);
    return it == cpus.end() ? -1 : static_cast<int>(it - cpus.begin());
  };
  std::vector<std::size_t> free;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (tasks[i]->cpu) {
      out[i] = *tasks[i]->cpu;
      if (const int s = slot_of(*tasks[i]->cpu); s >= 0) {
        load[static_cast<std::size_t>(s)] += utilisation(*tasks[i]);
        ++count[static_cast<std::size_t>(s)];
      }
    } else {
      free.push_back(i);
    }
  }
  std::stable_sort(free.begin(), free.end(),
                   [&](std::size_t a, std::size_t b) { return utilisation(*tasks[a]) > utilisation(*tasks[b]); });
  for (const std::size_t i : free) {
    std::size_t best = 0;
    for (std::size_t s = 1; s < cpus.size(); ++s)
      if (std::tie(load[s], count[s]) < std::tie(load[best], count[best])) best = s;
    if (cpus.empty()) break;
    out[i] = cpus[best];
    load[best] += utilisation(*tasks[i]);
    ++count[best];
  }
  return out;
}

}  // namespace

std::int64_t planned_cost_ns(const TaskSpec& task) {
  if (task.wcet_ns) return *task.wcet_ns;
  return task.virtual_exec_ns;
}

std::vector<int> subsystem_cpus(const SubsystemSpec& spec) {
  if (!spec.cpus.empty()) return spec.cpus;
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  std::vector<int> all(static_cast<std::size_t>(std::max(1L, n)));
  std::iota(all.begin(), all.end(), 0);
  return all;
}

SchedulePlan make_schedule_plan(const ResolvedSubsystem& subsystem, const ReleaseOrder& order,
                                const std::vector<int>& cpus, const std::vector<std::string>& configuration) {
  SchedulePlan plan;
  plan.policy = subsystem.spec->scheduler;
  std::vector<const TaskSpec*> specs;
  for (const auto& t : subsystem.tasks) specs.push_back(t.spec);
  plan.cpu = assign(specs, cpus);

  for (std::size_t i = 0; i < specs.size(); ++i) {
    const TaskSpec& t = *specs[i];
    TaskUrgency u;
    u.background = !t.period_ns && !t.server;
    u.period_ns = t.period_ns ? *t.period_ns : (t.server ? t.server->period_ns : 0);
    u.deadline_ns = t.deadline_ns > 0 ? t.deadline_ns : u.period_ns;
    u.user_priority = t.priority;
    u.rank = order.rank[i];
    u.index = static_cast<int>(i);
    u.critical = t.criticality == Criticality::kHard;
    plan.urgency.push_back(u);
  }

  // MUF's critical set, per CPU: the hard tasks, then the others by shortest period while the
  // worst-case utilisation stays at or under 100%. A task of unknown cost adds nothing.
  const auto in_config = [&](std::size_t i) {
    return std::find(configuration.begin(), configuration.end(), specs[i]->name) != configuration.end();
  };
  for (const int cpu : cpus) {
    double used = 0.0;
    std::vector<std::size_t> soft;
    for (std::size_t i = 0; i < specs.size(); ++i) {
      if (plan.cpu[i] != cpu || !in_config(i) || plan.urgency[i].background) continue;
      if (plan.urgency[i].critical)
        used += utilisation(*specs[i]);
      else
        soft.push_back(i);
    }
    std::stable_sort(soft.begin(), soft.end(), [&](std::size_t a, std::size_t b) {
      return plan.urgency[a].period_ns < plan.urgency[b].period_ns;
    });
    for (const std::size_t i : soft) {
      if (used + utilisation(*specs[i]) > 1.0) break;
      used += utilisation(*specs[i]);
      plan.urgency[i].critical = true;
    }
  }
  return plan;
}

}  // namespace chimera
