#pragma once
// One task of a configuration as schedulability analysis sees it: plain numbers, no module, no
// thread. The runtime (CPU assignment, MUF's critical set) and `chimera analyze` share it.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace chimera::analysis {

/// Where a task's execution time C came from.
enum class WcetSource {
  kUnknown,    // nowhere: analysis cannot bound the task
  kFile,       // the subsystem file's `wcet:`
  kProfile,    // a profile file (`chimera analyze --wcet-from`, written by `chimera profile`)
  kMeasured,   // a short virtual-clock run by `chimera analyze`: host time, with a safety margin
  kVirtual,    // the file's `virtual_exec:`, the simulated cost (the virtual clock's own plan)
  kSimulated,  // a short virtual-clock run: the simulated time (virtual_exec plus what the module charged)
};

std::string_view wcet_source_name(WcetSource source);

struct TaskModel {
  std::string name;
  /// C, the longest execution of one cycle; for a server its budget per period. 0: unknown.
  std::int64_t wcet_ns = 0;
  /// A server only: the longest execution of one job it serves. The runtime starts a job while
  /// any budget remains and charges it when it ends, so a server can run over its budget by up
  /// to one job: analysis counts budget + job_wcet_ns per period. 0: unknown.
  std::int64_t job_wcet_ns = 0;
  /// T; a server's replenishment period; 0: aperiodic without a server (background).
  std::int64_t period_ns = 0;
  /// D, relative to the release; 0 means the period.
  std::int64_t deadline_ns = 0;
  bool hard = true;
  /// MUF's third level of urgency: higher is more urgent.
  int user_priority = 0;
  /// An aperiodic (sporadic) server: budget wcet_ns every period_ns.
  bool server = false;
  /// The CPU the file pins the task to, or -1: assign_cpus() chooses.
  int cpu = -1;
  /// Position in the file: the last tie-break everywhere.
  int file_index = 0;
  WcetSource wcet_source = WcetSource::kUnknown;
  /// The task's same-rate chain (analysis/release_order.hpp) within its process: tasks of one
  /// chain and one process have the same value, the file index of the first of them. -1: a chain
  /// of its own. CPU assignment keeps a chain on one CPU where it fits.
  int chain = -1;
  /// The file indices of the same-period tasks whose job of the same release this task waits for
  /// before it starts (the same-rate rule). On another CPU, that wait is the task's release jitter.
  std::vector<int> same_rate_producers{};
  /// Release jitter: how long after its release the task may wait for those producers when they
  /// run on another CPU. analyse_configuration() finds it from their response times.
  std::int64_t release_jitter_ns = 0;
  /// The C a run knows before it starts (the file's `wcet:`, else its `virtual_exec:`; for a
  /// server its longest job), 0: unknown; task_models() sets it. nullopt (a model made by hand):
  /// the C above. The runtime builds MUF's critical set from it.
  std::optional<std::int64_t> run_wcet_ns = std::nullopt;
};

/// The C (for a server its longest job) a run knows before it starts; 0: unknown.
[[nodiscard]] inline std::int64_t run_known_wcet(const TaskModel& task) {
  return task.run_wcet_ns.value_or(task.server ? task.job_wcet_ns : task.wcet_ns);
}

/// The task as a run sees it before it starts: its C (a server's longest job) is run_known_wcet().
[[nodiscard]] TaskModel as_the_run_knows(const TaskModel& task);

/// The framework's own cost of one cycle that the module's C does not contain (release, dispatch,
/// the state-variable transfers and the statistics: docs/scheduling.md). 1 µs is the project's
/// budget for it (GUIDE: framework overhead per task cycle <= 1 µs).
inline constexpr std::int64_t kDefaultOverheadNs = 1'000;

struct AnalysisOptions {
  /// Added to every task's C, once per cycle (for a server once per period).
  std::int64_t overhead_ns = kDefaultOverheadNs;
};

/// C, T and D of one task as the tests use them: the analysed C (with the overhead, and for a
/// server its possible overrun), the period and the relative deadline.
struct Demand {
  std::int64_t c_ns = 0;
  std::int64_t t_ns = 0;
  std::int64_t d_ns = 0;
  /// Release jitter J: how long after its release a job may become ready. Here, the wait for a
  /// same-rate producer on another CPU; its job still has to finish by release + D.
  std::int64_t j_ns = 0;
};

/// An aperiodic task without a server: it runs in the background and takes no part in analysis.
[[nodiscard]] inline bool is_background(const TaskModel& task) { return task.period_ns <= 0; }

/// D, or T when the task has no deadline of its own.
[[nodiscard]] inline std::int64_t relative_deadline(const TaskModel& task) {
  return task.deadline_ns > 0 ? task.deadline_ns : task.period_ns;
}

/// Whether the execution time analysis needs is known (for a server: budget and longest job).
[[nodiscard]] inline bool wcet_known(const TaskModel& task) {
  return task.wcet_ns > 0 && (!task.server || task.job_wcet_ns > 0);
}

/// The C analysis uses: wcet + overhead, for a server budget + longest job + overhead; nullopt
/// when unknown or for a background task.
[[nodiscard]] std::optional<Demand> demand_of(const TaskModel& task, const AnalysisOptions& options);

}  // namespace chimera::analysis
