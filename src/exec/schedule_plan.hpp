#pragma once
// Where each task of a subsystem runs and how the file's policy ranks it: the CPU assignment
// (pinned by `cpu:` or automatic) and, per configuration, each task's urgency data (MUF's
// critical set among them). Computed off the real-time path, before start and at each switch.

#include <string>
#include <vector>

#include "chimera/analysis/release_order.hpp"
#include "chimera/config/verify.hpp"
#include "urgency.hpp"

namespace chimera {

struct SchedulePlan {
  SchedulerKind policy = SchedulerKind::kRm;
  std::vector<int> cpu;              // per task of the file: the CPU it runs on
  std::vector<TaskUrgency> urgency;  // per task of the file
};

/// Plans every task of the file on `cpus` (the CPUs the subsystem may use) as `chimera analyze`
/// does (analysis/cpu_assignment.hpp), with MUF's critical set computed for the tasks of
/// `configuration` (the others are planned as if alone). Not real-time safe.
SchedulePlan make_schedule_plan(const ResolvedSubsystem& subsystem, const analysis::ReleaseOrder& order,
                                const std::vector<int>& cpus, const std::vector<std::string>& configuration);

/// The CPUs a subsystem may use: the file's `cpus`, or every online CPU.
std::vector<int> subsystem_cpus(const SubsystemSpec& spec);

}  // namespace chimera
