#pragma once
// From a subsystem file to the task models analysis works on: the one place where the file's
// keys become analysis's numbers (C, T, D, criticality, priority, server, pinning).

#include <span>
#include <string>
#include <vector>

#include "chimera/analysis/release_order.hpp"
#include "chimera/analysis/task_model.hpp"
#include "chimera/analysis/wcet_profile.hpp"
#include "chimera/config/subsystem.hpp"

namespace chimera::analysis {

/// The models of the tasks named (a configuration's), in file order whatever the order of
/// `task_names`; names that are not tasks of `spec` are left out. C comes from, in order: the
/// task's `wcet:`, then `profile`, then `measured` (either may be null; a measured entry in
/// simulated time is WcetSource::kSimulated), then the task's
/// `virtual_exec:` (the simulated cost the virtual clock's plan uses); otherwise it is unknown
/// (0, WcetSource::kUnknown). A task with `server:` becomes a server model: wcet_ns = the budget,
/// period_ns = the server's period, and the C found as above is its longest job (job_wcet_ns).
/// `priority:` is the user priority; run_wcet_ns is `wcet:`, else `virtual_exec:`. With `order` (the
/// file's release order) each model also gets its chain and the same-rate producers it waits for
/// among the tasks named. Not real-time safe.
[[nodiscard]] std::vector<TaskModel> task_models(const SubsystemSpec& spec, std::span<const std::string> task_names,
                                                 const WcetProfile* profile = nullptr,
                                                 const WcetProfile* measured = nullptr,
                                                 const ReleaseOrder* order = nullptr);

}  // namespace chimera::analysis
