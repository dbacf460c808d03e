#pragma once
// What a running subsystem is made of (private to the control part): shared by subsystem.cpp,
// the operations of the subsystem interface, and subsystem_assembly.cpp, the live assembly's.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <utility>
#include <vector>

#include "chimera/control/subsystem.hpp"
#include "chimera/svt/global_table.hpp"
#include "exec/event_log.hpp"
#include "exec/executive.hpp"
#include "exec/task_block.hpp"
#include "exec/task_set.hpp"
#include "flight_recorder.hpp"
#include "reconfig/reconfiguration.hpp"
#include "reconfig/request_board.hpp"

namespace chimera {

// Members in the order they are made; each refers only to those above it. The runtime (from
// `resolution` to `reconfiguration`) is made by build_runtime() at create, and made anew when the
// live assembly adds a task (while no task is created).
struct Subsystem::Impl {
  SubsystemSpec spec;  // the resolution points into this copy, which never moves
  RunOptions options;
  const Registry* registry = nullptr;  // for the live assembly's re-resolution; outlives the subsystem
  Resolution resolution;
  std::unique_ptr<GlobalTable> table;
  std::unique_ptr<TaskBlock> block;  // module processes' tasks' shared slots (docs/processes.md); null: none
  std::unique_ptr<SubsystemRequestBoard> requests;  // in the block's slots when there is one: declared after it
  std::unique_ptr<TaskSet> tasks;
  std::unique_ptr<FlightRecorder> recorder;   // the tasks write into it; null: none kept
  std::vector<std::uint64_t> dumped_failure;  // per task, the failure its ERROR dump was for; run_for's thread only
  std::unique_ptr<EventLog> events;
  std::unique_ptr<Executive> executive;
  std::unique_ptr<Reconfiguration> reconfiguration;
  // Signals, switches, set, the live assembly and stop, one at a time; never taken by a task's
  // thread. Queries (snapshot, events, get, the flag) do not take it: they answer while a switch
  // is under way.
  mutable std::mutex ops_mutex;
  // The runtime's lifetime for the queries that read it without ops_mutex (shared): stop() takes
  // it alone to remove the table, the live assembly's rebuild to replace the whole runtime.
  mutable std::shared_mutex runtime_mutex;
  std::atomic<bool> stopped{false};  // written under ops_mutex; read by queries on their own (seq_cst: rare, simplest)
  bool serving = false;              // start() has asked the executive to serve; under ops_mutex
  // Per task, what the operator and the run need to know beyond its state, written under
  // ops_mutex and read by queries that do not take it (notes_mutex):
  // which of its failures a clear (or a kill) took it out of ERROR from, so that status tells a
  // past error from the present state;
  struct ErrorEnd {
    std::uint64_t failure = 0;  // TaskFailure::number; 0: none ended yet
    Signal by = Signal::kClear;
    std::int64_t at_ns = 0;
  };
  // and what its module reported when a kill found a fault (whole: an event's text is bounded);
  // and whether the live assembly removed it (it stays, NOT-CREATED and out of sight, until the
  // runtime is next rebuilt, so that no index of the executive changes).
  mutable std::mutex notes_mutex;
  std::vector<ErrorEnd> error_ends;
  std::vector<std::string> kill_faults;
  std::vector<bool> removed;
  // What earlier runtimes (before an add rebuilt it) left that the run still reports.
  std::vector<Event> earlier_events;        // not drained yet
  std::vector<std::string> earlier_faults;  // faults() lines
  std::vector<std::string> left_behind;     // tasks whose thread stop() left behind, stuck in a method
  // watch_writes(): each variable's watch, applied to every executive build_runtime() makes.
  std::vector<std::pair<std::string, std::shared_ptr<WriteWatch>>> watches;
  bool earlier_hard_failure = false;
  // report_remote_imports(): set and called from the thread that drives the commands.
  RemoteImportsReport remote_imports;
  // build_runtime()'s count. Release after the table is made, acquire by runtimes_built(): who
  // sees the new count finds the new region under the table's name.
  std::atomic<std::uint64_t> runtimes_built{0};

  void note_kill(std::size_t task, const Result<void>& killed) {
    if (killed || killed.error().code != Errc::kModuleFault) return;
    std::lock_guard<std::mutex> notes(notes_mutex);
    kill_faults[task] = killed.error().message;
  }
  /// The paper's two-step termination (stop, open): every task ON turned off, then every created
  /// task killed, signal by signal, so that what a module's kill reports is kept. Under ops_mutex.
  void off_then_kill_every_task() {
    for (std::size_t i = 0; i < tasks->size(); ++i)
      if ((*tasks)[i].state() == TaskState::kOn) (void)executive->signal(i, Signal::kOff);
    for (std::size_t i = 0; i < tasks->size(); ++i)
      if ((*tasks)[i].state() != TaskState::kNotCreated) note_kill(i, executive->signal(i, Signal::kKill));
  }
  /// Whether task `i` was removed by the live assembly.
  [[nodiscard]] bool is_removed(std::size_t i) const {
    std::lock_guard<std::mutex> notes(notes_mutex);
    return removed[i];
  }
  /// The index of a task that exists (not removed), by name.
  [[nodiscard]] std::optional<std::size_t> live_index(std::string_view name) const {
    const auto i = tasks->index_of(name);
    return i && !is_removed(*i) ? i : std::nullopt;
  }
  /// The flight recorder's dump for each task that entered ERROR since the last call (each failure
  /// once), into options.error_dump_dir, announced by an event. From run_for's thread.
  void dump_new_errors();
  /// The subsystem as it stands: its tasks less the removed ones, the configuration on as `start`.
  /// From the thread that drives the commands, the only one that changes the spec.
  [[nodiscard]] SubsystemSpec live_spec() const;
  /// Each task's state and last error, for a dump's summary.
  [[nodiscard]] std::vector<std::string> summary_lines() const;
  /// The fault lines of the current runtime's tasks (faults() adds the earlier ones).
  [[nodiscard]] std::vector<std::string> runtime_faults() const;
  /// Resolves `spec`, creates the table and the runtime on it, with `configuration` on and the
  /// clock starting at `start_ns`. Refuses an illegal `configuration` before it creates anything.
  /// Callers hold ops_mutex and runtime_mutex (or own the subsystem alone). Not real-time safe.
  Result<void> build_runtime(const std::string& configuration, std::int64_t start_ns);
  /// The live assembly's rebuild, while no task is created: the runtime ends (what it leaves to
  /// report is kept) and is made anew for `next` with `configuration` on, the clock going on.
  /// Should the machine refuse it, `current` is made again with `current_configuration`, and the
  /// refusal returned. Callers hold ops_mutex (not runtime_mutex: it is taken here).
  Result<void> rebuild_runtime(SubsystemSpec next, const std::string& configuration, const SubsystemSpec& current,
                               const std::string& current_configuration);
};

/// Refuses a task pinned to a CPU this machine does not have.
Result<void> check_task_cpus(const SubsystemSpec& spec);

}  // namespace chimera
