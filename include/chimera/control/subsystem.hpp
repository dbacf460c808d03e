#pragma once
// A running subsystem as the subsystem interface drives it (paper 3.3: the signals "from a user
// through a command-line or graphical interface, from an external subsystem"): the global table,
// its tasks, the executive that releases them on the real clock (real-time threads) or the
// virtual clock (deterministic, as fast as the machine allows), and its reconfiguration. The
// shell, the CLI and the network API all drive it through this API.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/config/verify.hpp"
#include "chimera/control/remote_imports.hpp"
#include "chimera/core/result.hpp"
#include "chimera/exec/clock.hpp"
#include "chimera/exec/event.hpp"
#include "chimera/exec/stats.hpp"
#include "chimera/lifecycle/state.hpp"
#include "chimera/module/registry.hpp"
#include "chimera/reconfig/switch_record.hpp"

namespace chimera {

class WriteWatch;

struct RunOptions {
  ClockKind clock = ClockKind::kReal;
  std::optional<std::string> configuration;  // default: the file's start configuration
  /// Suffix for the shared memory name, so that tests running in parallel do not collide.
  std::string shm_suffix;
  /// Ask for SCHED_FIFO and mlockall (real clock); falls back with one warning if refused.
  bool realtime_priorities = true;
  /// Real clock: measure every task's execution time as its thread's CPU time (profiling), not
  /// only that of tasks with a wcet budget. Costs two system calls a cycle.
  bool measure_cpu_time = false;
  /// Count allocations inside each task's on(), cycle(), off() and sync() (`chimera run
  /// --rt-check`). Only a program that installs the allocator hook of chimera/exec/rt_check.hpp
  /// sees any: the chimera command does; elsewhere the counts stay 0.
  bool rt_check = false;
  /// Real clock, a file with module processes (docs/processes.md): the chimera binary that runs
  /// them ("": this program, /proc/self/exe). A program that is not chimera names it.
  std::string worker_program;
  /// The flight recorder (docs/flight-recorder.md): how many seconds of every produced variable
  /// and of every task's cycles are kept in memory (0: none; a history that would need more than
  /// 256 MiB is shortened to fit). With module processes the rings are shared memory that their
  /// tasks write into as well.
  double record_seconds = 0;
  /// Where the recorder's dump goes when a task enters ERROR: a directory below this one, named
  /// after the subsystem, the task and the time ("": no dump then).
  std::string error_dump_dir;
};

/// One task as the subsystem interface sees it.
struct TaskSnapshot {
  std::string name;
  std::string module;
  TaskState state = TaskState::kNotCreated;
  std::int64_t period_ns = 0;
  int cpu = 0;  // the CPU it runs on (pinned by the file or assigned)
  TaskStatsSnapshot stats;
  std::string last_error;          // the last method failure, "" if none
  std::int64_t last_error_ns = 0;  // when it happened, on the subsystem's clock
  /// How the task left the ERROR that its last error put it in, if it has: the operator's
  /// `clear` (or a `kill`), and when. Empty while that error is current, or if it never put the
  /// task in ERROR (a failure error() recovered, an init that failed).
  std::optional<Signal> error_ended_by;
  std::int64_t error_ended_ns = 0;
};

class Subsystem {
 public:
  /// What it is made of: opaque here, defined in src/control (the live assembly's files share it).
  struct Impl;

  /// Resolves and verifies the file, creates the global table in shared memory. Refuses an
  /// illegal start configuration. Not real-time safe.
  /// `registry` outlives the subsystem (the live assembly resolves added tasks with it).
  static Result<std::unique_ptr<Subsystem>> create(const SubsystemSpec& spec, const Registry& registry,
                                                   RunOptions options);
  ~Subsystem();
  Subsystem(const Subsystem&) = delete;
  Subsystem& operator=(const Subsystem&) = delete;

  /// Spawns then turns on every task of the start configuration. If any init fails, everything
  /// spawned so far is killed and the error returned: never a partial start.
  Result<void> start();
  /// Sends a lifecycle signal to one task and waits until its thread has carried it out.
  Result<void> signal(std::string_view task, Signal signal);
  /// Lets the subsystem run for `ns`: simulated time on the virtual clock, a sleep on the real one.
  /// Switches that tasks ask for are carried out meanwhile (on the virtual clock at the very
  /// instant they are asked for).
  void run_for(std::int64_t ns);

  /// Dynamic reconfiguration to configuration `name` (paper 3.4, docs/reconfiguration.md): the
  /// target is verified, its tasks that do not exist yet are created (init) while the current
  /// configuration runs on, with the illegal-configuration flag raised meanwhile; then at one
  /// cycle boundary the leaving tasks turn off and the joining ones on, and the tasks that stay
  /// ON keep their rate without losing a cycle. Consumers of an in-const whose value changed get
  /// reinit() before their next cycle. An unknown or illegal target, or one with a task in
  /// ERROR, is refused and nothing changes. `cause` is logged ("operator" by default). Not
  /// real-time safe.
  Result<SwitchRecord> switch_to(std::string_view name, std::string_view cause = "operator");
  /// The configuration that is on now.
  [[nodiscard]] std::string configuration() const;
  /// Every switch carried out so far, oldest first; from the `first`-th on if given.
  [[nodiscard]] std::vector<SwitchRecord> switches(std::size_t first = 0) const;
  /// Off, then kill, every task; removes the shared memory. Idempotent. Afterwards snapshot()
  /// and drain_events() still answer (the run's figures and last events); signal, get and set
  /// are refused.
  void stop();

  /// Time since start on the subsystem's clock.
  [[nodiscard]] std::int64_t now_ns() const;
  [[nodiscard]] ClockKind clock() const;
  /// The subsystem's model; the live assembly changes it (read it from the thread that drives
  /// the commands).
  [[nodiscard]] const SubsystemSpec& spec() const;
  [[nodiscard]] const ResolvedSubsystem& resolved() const;
  /// Whether the task at `index` of spec().tasks (and resolved().tasks) was removed by the live
  /// assembly's `remove`: it stays in both, out of sight, until the next add or open rebuilds them.
  [[nodiscard]] bool removed(std::size_t index) const;
  /// The module library its tasks are made from (and the live assembly adds from).
  [[nodiscard]] const Registry& registry() const;
  /// Whether the illegal-configuration flag is up now (paper 3.4). Any thread.
  [[nodiscard]] bool illegal_configuration() const;
  /// From now on until the stop, `watch` is woken each time a task of this process publishes
  /// `variable` (chimera/exec/write_watch.hpp), also after the live assembly rebuilds the runtime:
  /// how the DDS bridge learns of its exports' new values without polling the table. Tasks in
  /// module processes wake nobody. Refuses a variable the table does not hold. Call it from the
  /// thread that drives the commands. Not real-time safe.
  Result<void> watch_writes(const std::string& variable, std::shared_ptr<WriteWatch> watch);
  /// How many times the runtime (and with it the table, a new region under the same name) has
  /// been made: 1 after create, one more for each task the live assembly added. Whoever attached
  /// to the table by its name (the DDS bridge) attaches again when it changes. Any thread.
  [[nodiscard]] std::uint64_t runtimes_built() const;
  /// From now on `status` (the shell's and the network API's) shows the imports that `report`
  /// tells of: how the DDS bridge, which lives above this part, makes them visible. An empty
  /// function: none. Call it from the thread that drives the commands, while no command runs
  /// (the report is called under the command gate). Not real-time safe.
  void report_remote_imports(RemoteImportsReport report);
  /// What the report tells now, in file order; none without one. Not real-time safe.
  [[nodiscard]] std::vector<RemoteImport> remote_imports() const;

  // The live assembly (docs/control-api.md, "Live assembly"), what ros2_control users do with
  // load, configure and switch. Each refuses, changing nothing, what it cannot carry out, with one
  // line saying why. Call them from the thread that drives the commands (the command gate), as
  // run_for(). Not real-time safe.

  /// Adds a task to the subsystem, NOT-CREATED: `entry` is one entry of a file's `tasks:` list as
  /// a YAML flow mapping, `{name: pid, module: pid_joint, period: 1ms, params: {kp: 5}}`, checked
  /// as the loader checks a file. The running executive is made anew for the larger set of tasks,
  /// which it can only be while no task is created: refused while any task is OFF, ON or ERROR.
  /// Returns the new task's name.
  Result<std::string> add_task(std::string_view entry);
  /// Defines configuration `name` (new, or one that is not on) as `tasks`, whether legal or not:
  /// verify_configuration() says, and switch_to() refuses an illegal one.
  Result<void> define_configuration(std::string_view name, const std::vector<std::string>& tasks);
  /// The violations of configuration `name` (the paper's equations 1 and 2 and the size rule);
  /// empty if it is legal. Never switches.
  [[nodiscard]] Result<std::vector<Violation>> verify_configuration(std::string_view name) const;
  /// Removes a task that no configuration (and no `requests:` entry) names; one that is created
  /// is killed first, one that is ON is refused.
  Result<void> remove_task(std::string_view name);
  /// The subsystem as a subsystem file, its `start:` the configuration on now: what `chimera
  /// verify` accepts and `chimera run` starts as this subsystem. Refused while a configuration is
  /// illegal or there is no task (a file has at least one).
  [[nodiscard]] Result<std::string> save_yaml() const;
  /// Replaces the subsystem with another file's (`next`, as the loader read it), keeping the run,
  /// its clock and options: every task is turned off and killed, the runtime is made anew for
  /// `next` and its `start` configuration turned on, as chimera run starts a file. Refused,
  /// changing nothing, when `next` is not legal (its start configuration) or pins a CPU this
  /// machine lacks. `chimera run`'s DDS bridge follows the new table to `next`'s exports and imports.
  Result<void> replace(SubsystemSpec next);
  /// The names of the configurations, in definition order. Any thread.
  [[nodiscard]] std::vector<std::string> configurations() const;

  /// The current value of a variable, converted to doubles; and a write by the operator,
  /// refused if an ON task produces the variable.
  Result<std::vector<double>> get(std::string_view variable) const;
  Result<void> set(std::string_view variable, const std::vector<double>& values);

  /// The flight recorder's history, written into directory `dir` (docs/flight-recorder.md):
  /// variables.csv, timing.csv, summary.txt; `why` goes into the summary. `dir` empty: one named
  /// after the subsystem and the time, below RunOptions::error_dump_dir (or chimera-dumps).
  /// Returns the directory written. Refused when the run keeps no history (record_seconds 0).
  /// The tasks run on meanwhile. Not real-time safe.
  Result<std::string> dump(const std::string& dir, std::string_view why) const;
  /// How many seconds of history the flight recorder keeps (0: none).
  [[nodiscard]] double recorded_seconds() const;

  /// Every task's state and figures; last_error is current without draining events.
  [[nodiscard]] std::vector<TaskSnapshot> snapshot() const;
  /// Every task's name and state, in task order: snapshot() without the figures, cheap enough to
  /// be asked many times a second of a thousand tasks. Any thread.
  [[nodiscard]] std::vector<std::pair<std::string, TaskState>> states() const;
  /// Events since the last call (drained from the tasks' real-time rings).
  std::vector<Event> drain_events();
  /// Whether any hard task ended up in ERROR during the run.
  [[nodiscard]] bool hard_task_failed() const;
  /// Why the run has not been clean, one line each in task order ("" none): every hard task that
  /// entered ERROR (with its last error), and every task whose module reported a fault as it was
  /// killed (a resource not released cleanly: a data logger's lost rows). `chimera run` exits 1
  /// on any. Not real-time safe.
  [[nodiscard]] std::vector<std::string> faults() const;

 private:
  friend class SubsystemTestAccess;  // tests: the table itself (src/control/subsystem_test_access.hpp)
  Subsystem();
  /// From now on the switches tasks ask for are carried out.
  void serve_requests();
  std::unique_ptr<Impl> impl_;
};

}  // namespace chimera
