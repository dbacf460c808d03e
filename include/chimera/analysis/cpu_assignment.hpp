#pragma once
// Which CPU each task of a configuration runs on: the file's `cpu:` where given, otherwise
// worst-fit decreasing by utilisation, each task on the least-loaded CPU that stays schedulable.
// docs/scheduling.md says why worst fit rather than first fit.

#include <span>
#include <vector>

#include "chimera/analysis/release_order.hpp"
#include "chimera/analysis/task_model.hpp"
#include "chimera/config/subsystem.hpp"

namespace chimera::analysis {

/// The CPU of every task, in the order given. Deterministic: the same tasks and CPUs give the
/// same answer. Tasks of one same-rate chain (TaskModel::chain) are placed as one unit, so that
/// none waits for its producer on another CPU.
/// - A pinned task (cpu >= 0) stays where it is, whether or not `cpus` lists its CPU; the rest of
///   its chain goes there too where it fits.
/// - The units whose every C is known, by utilisation C/T from the largest (ties: shorter period,
///   then file order), each go whole on the least-loaded CPU of `cpus` (ties: lower number) on
///   which the tasks of known C stay schedulable under `scheduler` (analyse_cpu()). A chain that
///   fits on no CPU whole is split: its tasks go one by one, largest first, on the least-loaded
///   CPU where each fits, or the least-loaded one, and analysis says what misses.
/// - Last, units whose share is unknown (some C unknown, or aperiodic without a server): shortest
///   period first, background tasks after, each whole on the CPU with the fewest such tasks, then
///   the lowest known load, then the lower number: spread evenly, never all on one CPU.
/// With `cpus` empty the unpinned tasks get -1. Not real-time safe.
[[nodiscard]] std::vector<int> assign_cpus(std::span<const TaskModel> tasks, std::span<const int> cpus,
                                           SchedulerKind scheduler, const AnalysisOptions& options = {});

/// The CPU of every task of the file (in file order), assigned from what a run knows before it
/// starts: the file's `wcet:` (and a server's budget), `cpu:` and its same-rate chains (`order`,
/// the file's release order). Every task of the file takes part, whichever configuration it is
/// in, so that a task keeps its CPU across switches. The runtime and `chimera analyze` both call
/// this, so the assignment analysed is the one run. Not real-time safe.
[[nodiscard]] std::vector<int> assign_subsystem_cpus(const SubsystemSpec& spec, const ReleaseOrder& order,
                                                     std::span<const int> cpus, const AnalysisOptions& options = {});

/// The CPUs a subsystem may use: the file's `cpus:`, or 0 .. online_cpus - 1 when it has none.
[[nodiscard]] std::vector<int> allowed_cpus(const SubsystemSpec& spec, int online_cpus);

}  // namespace chimera::analysis
