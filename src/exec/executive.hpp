#pragma once
// The executive (the paper's "RTOS services", 3.3): what releases a subsystem's tasks under the
// file's policy, carries out the paper's signals between their cycles and commits switches at a
// cycle boundary. One interface, two clocks: the real executive (real-time threads on
// CLOCK_MONOTONIC) and the virtual one (a discrete-event simulation of the same schedule, the
// tests' oracle), both following release_policy.hpp. The subsystem, the reconfiguration and the
// control talk only to this interface, and none of them chooses a clock: make_executive() does,
// once. Tasks whose modules run in module processes are behind one more implementation, which
// routes each signal to the process that runs the task (process_executive.hpp).
//
// Exported to the parts above. Nothing here is real-time safe: none of it runs in a cycle.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "chimera/config/verify.hpp"
#include "chimera/core/result.hpp"
#include "chimera/exec/clock.hpp"
#include "chimera/lifecycle/state.hpp"
#include "chimera/svt/global_table.hpp"
#include "doorbell.hpp"
#include "event_log.hpp"
#include "task.hpp"

namespace chimera {

class TaskBlock;
class WriteWatch;

/// What the main process needs to run tasks in module processes (docs/processes.md).
struct ProcessSetup {
  TaskBlock* block = nullptr;            // the tasks' shared slots; null: no module processes
  std::string worker_program;            // the chimera binary
  std::vector<std::string> worker_args;  // what every worker is told: the file, the table, options
  int history_fd = -1;                   // the flight recorder's shared rings (-1: none kept)
};

/// What an executive is made from.
struct ExecutiveSetup {
  ClockKind clock = ClockKind::kReal;
  /// Real clock: SCHED_FIFO and mlockall where the system allows them (one warning where not).
  bool realtime_priorities = true;
  /// Real clock: every task's execution time as its thread's CPU time (profiling), not only that
  /// of tasks with a wcet budget. Costs two system calls a cycle.
  bool measure_cpu_time = false;
  const ResolvedSubsystem* subsystem = nullptr;
  GlobalTable* table = nullptr;
  std::vector<Task*> tasks;                // every task of the file, in file order
  std::vector<std::string> configuration;  // the tasks that start: the first plan (MUF's critical set)
  EventLog* events = nullptr;              // where the executive's own events go (a job overdue)
  /// The time the executive's clock starts at: 0 for a new subsystem; for one rebuilt by the
  /// live assembly (a task added), the time its clock had reached, so that time goes on.
  std::int64_t start_ns = 0;
  /// Real clock: which tasks this process runs (empty: all). A module process hosts its own
  /// tasks; the main process those of no module process (docs/processes.md).
  std::vector<bool> hosted;
  /// Real clock: CLOCK_MONOTONIC at time 0 (0: now). A module process takes the main process's,
  /// so that every process's periodic releases fall on one grid.
  std::int64_t epoch_ns = 0;
  /// Real clock, a file with module processes: how to start them (process_executive.hpp).
  ProcessSetup processes;
  /// Real clock: per task, an eventfd to wake it by (an aperiodic task's bell) that the executive
  /// takes over instead of making its own; -1 or missing: its own. A module process is given the
  /// main process's, so that a producer in any process wakes an aperiodic task in any other.
  std::vector<int> bell_fds;
};

/// A switch's commit (docs/reconfiguration.md).
struct SwitchCommit {
  std::vector<std::size_t> leaving;  // ON now: off after their last release before the commit
  std::vector<std::size_t> joining;  // OFF now: on at the commit, released from it
  /// The switch created tasks, so it takes longer than a cycle: on the virtual clock the old
  /// configuration runs on to the next boundary first (the real clock simply took that long).
  bool slow = false;
  std::vector<std::string> target;  // the target configuration's tasks: the plan from the commit on
  /// The commit's instant on the executive's clock; -1: the next boundary of the fastest task
  /// involved that leaves time to post it. Given when several executives commit one switch.
  std::int64_t at_ns = -1;
  /// Which half to carry out: a switch across module processes makes every leaving task off, in
  /// every process, before any joining task turns on (one writer per variable at any time).
  enum class Part : std::uint8_t { kWhole, kLeave, kJoin } part = Part::kWhole;
};

/// What a commit did. The switch is carried out whatever a task's fault on the way.
struct CommitOutcome {
  /// The instant the joining tasks are released from (executive clock): the one asked for, or
  /// later when a leaving task had already run a release at or after it (a commit posted late),
  /// so that no release is run by two producers. A kLeave part gives what its join part must use.
  std::int64_t joins_from_ns = -1;
  Result<void> fault;  // the first task that failed to turn off or on, if any
};

/// What the subsystem interface asks the executive to serve while it runs.
struct ServiceHooks {
  Doorbell* requests = nullptr;          // rings when a module asks for a switch (rung to stop, too)
  std::function<void()> serve_requests;  // carries out (or refuses) the requests; takes the interface's locks
};

class Executive {
 public:
  Executive() = default;
  Executive(const Executive&) = delete;
  Executive& operator=(const Executive&) = delete;
  Executive(Executive&&) = delete;
  Executive& operator=(Executive&&) = delete;
  virtual ~Executive() = default;

  [[nodiscard]] virtual ClockKind clock() const noexcept = 0;
  /// Time since start on this executive's clock (after shutdown(): when it stopped).
  [[nodiscard]] virtual std::int64_t now_ns() const = 0;
  /// The CPU task `task` runs on (pinned by the file or assigned); it never changes. Any thread.
  [[nodiscard]] virtual int cpu_of(std::size_t task) const = 0;

  /// Carries out a lifecycle signal on one task, between its cycles, and returns once it is done.
  /// A signal the task's state does not allow is refused and changes nothing.
  virtual Result<void> signal(std::size_t task, Signal signal) = 0;
  /// Turns on the tasks `tasks` (OFF) as one: on() on each, then every one's first release at its
  /// first grid point at or after one common instant, so that none runs before all are on.
  virtual Result<void> turn_on_together(const std::vector<std::size_t>& tasks) = 0;
  /// A switch's commit at one cycle boundary of the fastest task involved: the leaving tasks off
  /// after their last release before it, the joining ones on and released from it, the others
  /// untouched; then the plan of `commit.target`.
  virtual CommitOutcome commit_switch(const SwitchCommit& commit) = 0;
  /// reinit() of task `task` between two of its cycles.
  virtual Result<void> reinit(std::size_t task) = 0;
  /// Lets the subsystem run for `ns`: simulated time on the virtual clock (the requests of
  /// ServiceHooks served at the very instant they are asked for), a sleep on the real one.
  virtual void run_for(std::int64_t ns) = 0;
  /// From now on serves `hooks`: the real clock with a service thread (which also watches for
  /// jobs running past their deadline), the virtual one inside run_for.
  virtual void serve(ServiceHooks hooks) = 0;
  /// Stops serving (the real clock's service thread ends) and returns once nothing of the hooks
  /// runs any more. Idempotent.
  virtual void stop_serving() = 0;
  /// Someone other than a task (the operator's `set`) wrote variable `v`: wakes its readers that
  /// are triggered by it.
  virtual void variable_written(VarIndex v) = 0;
  /// Stops serving, turns every task off, then kills it, and ends every thread. Idempotent. The
  /// tasks keep their figures and events; no signal may follow.
  virtual void shutdown() = 0;
  /// The run is ending, and must end within a bound (issue 15): from now on a task's thread that
  /// does not answer a signal within a second is taken for stuck in a method, every later signal
  /// to its tasks is refused at once, and shutdown() leaves it behind rather than wait for ever.
  virtual void begin_stop() = 0;
  /// The tasks whose thread shutdown() left behind, stuck in a method. Whatever that thread may
  /// still touch (its modules, tasks, this executive, the table) must then outlive the process.
  [[nodiscard]] virtual std::vector<std::string> left_behind() const = 0;
  /// From now on each publication of variable `v` by a task this process runs calls
  /// `watch->written()` (nullptr: no more). `watch` must outlive the executive or the next call
  /// for `v`. The virtual clock calls nothing: its time is not the watcher's. Any thread.
  virtual void watch_writes(VarIndex v, WriteWatch* watch) = 0;
};

/// The shortest period among the periodic tasks that leave or join in `commit` (0: none): a
/// switch commits at one of its boundaries.
std::int64_t shortest_period(const std::vector<Task*>& tasks, const SwitchCommit& commit);

/// The executive of `setup.clock`. Not real-time safe.
std::unique_ptr<Executive> make_executive(ExecutiveSetup setup);

}  // namespace chimera
