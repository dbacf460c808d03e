#pragma once
// A task: one port-based object instance with its local state variable table and lifecycle.
// The framework's non-virtual interface: every module method is called from here, wrapped in
// the state variable transfers, timed, and guarded so that a failure or an exception becomes
// the lifecycle's error path instead of escaping (paper 3.3, Figure 7).
//
// A task's methods are called by one thread at a time: its own thread on the real clock, the
// simulation thread on the virtual clock. state() and stats() may be read from anywhere.
//
// A task in ERROR holds the illegal-configuration flag (paper 3.4: it "can also be used to
// indicate the presence of an error in the system"): one hold, taken as it enters ERROR and given
// back as it leaves, so no interleaving with other raisers can lower the flag meanwhile.
// Exported to the parts above (not installed).

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/config/verify.hpp"
#include "chimera/core/history_rings.hpp"
#include "chimera/core/result.hpp"
#include "chimera/exec/stats.hpp"
#include "chimera/lifecycle/state.hpp"
#include "chimera/module/module.hpp"
#include "chimera/svt/global_table.hpp"
#include "chimera/svt/local_table.hpp"
#include "event_ring.hpp"
#include "task_shared.hpp"

namespace chimera {

/// One cycle as the flight recorder keeps it (docs/flight-recorder.md), stamped with its release
/// time; or, with kSkipped, releases that did not run.
struct CycleRecord {
  static constexpr std::uint64_t kMissed = 1;   // ended after its deadline
  static constexpr std::uint64_t kOverrun = 2;  // ran longer than its wcet budget
  static constexpr std::uint64_t kFailed = 4;   // its method failed (the error path ran)
  static constexpr std::uint64_t kSkipped = 8;  // not a cycle: `latency_ns` releases skipped (late: skip)
  std::int64_t latency_ns = 0;                  // release to start
  std::int64_t exec_ns = 0;                     // execution time, on the clock the statistics use
  std::int64_t response_ns = 0;                 // release to end
  std::uint64_t flags = 0;
};
static_assert(sizeof(CycleRecord) == 4 * sizeof(std::uint64_t), "the recorder reads a CycleRecord as four words");

class Task {
 public:
  static constexpr std::size_t kEventCapacity = TaskShared::kEventCapacity;

  /// `shared`: where its state, statistics and events live when other processes must see them
  /// (a slot of the task block, docs/processes.md); nullptr: in the task's own memory.
  Task(const ResolvedTask& resolved, GlobalTable& table, const SubsystemFlags& flags, TaskShared* shared = nullptr);
  /// Whether the task has an in-const bound to variable `name`.
  [[nodiscard]] bool reads_const(std::string_view name) const;
  /// The names of the variables its out-consts are bound to.
  [[nodiscard]] std::vector<std::string> const_outputs() const;
  ~Task();
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;

  [[nodiscard]] const std::string& name() const { return spec_.name; }
  [[nodiscard]] const TaskSpec& spec() const { return spec_; }
  [[nodiscard]] const ResolvedTask& resolved() const { return resolved_; }
  [[nodiscard]] bool periodic() const { return spec_.period_ns.has_value(); }
  [[nodiscard]] std::int64_t period_ns() const { return spec_.period_ns.value_or(0); }
  [[nodiscard]] bool hard() const { return spec_.criticality == Criticality::kHard; }

  /// Current lifecycle state. Real-time safe, any thread.
  [[nodiscard]] TaskState state() const noexcept { return shared_->state.load(std::memory_order_acquire); }

  /// Carries out a lifecycle signal: spawn calls init (allocation allowed), on calls on, off
  /// calls off, kill calls off if ON then kill, clear calls clear. `now_ns` stamps events.
  /// A signal the current state does not allow is refused and changes nothing.
  Result<void> apply(Signal signal, std::int64_t now_ns);

  /// How a job's execution time is measured on the real clock.
  enum class ExecClock : std::uint8_t {
    kWall,  // CLOCK_MONOTONIC from start to end (includes preemption); cheap
    kCpu,   // the thread's CPU time: exact, two system calls a cycle (tasks with a wcet, profiling)
  };

  /// Starts one job released at `release_ns`, at `start_ns` (subsystem clock): in-vars in, sync()
  /// for an aperiodic task, then cycle(); a failure takes the error path. The job's outputs stay
  /// in the local table until end_job(). Returns the job's simulated execution time for the
  /// virtual clock (the task's virtual_exec plus what the module charged), or -1 if the task is
  /// not ON. Real-time safe for the framework's part.
  std::int64_t begin_job(std::int64_t release_ns, std::int64_t start_ns) noexcept;
  /// Ends the job begun last at `end_ns`: out-vars out, statistics, timing checks. `used_ns` is
  /// the execution time that counts against the wcet budget (simulated on the virtual clock; -1:
  /// measure it, real clock). A deadline miss or budget overrun of a hard task calls error()
  /// (ERROR unless it recovers); a soft task only counts it. Returns the execution time counted
  /// (`used_ns`, or what was measured). Real-time safe.
  std::int64_t end_job(std::int64_t end_ns, std::int64_t used_ns) noexcept;
  /// Whether a job has begun and not yet ended.
  [[nodiscard]] bool job_open() const noexcept { return job_.open; }
  /// A producer of one of its in-consts changed its value (a switch): the new values are read
  /// into the local table, then reinit(); a failure takes the error path. Between cycles only,
  /// on the task's thread. Returns whether the task is still ON. Real-time safe for the framework.
  bool reinit(std::int64_t now_ns) noexcept;
  /// How many times reinit() ran since spawn.
  [[nodiscard]] std::uint64_t reinits() const noexcept { return reinits_.load(std::memory_order_relaxed); }
  /// `n` releases that will not run (late: skip), each a missed deadline; a hard task gets
  /// error(). Real-time safe.
  void skip_releases(std::uint64_t n, std::int64_t now_ns) noexcept;
  /// The deadline of a job released at `release_ns` (0 relative deadline: none, INT64_MAX).
  [[nodiscard]] std::int64_t absolute_deadline(std::int64_t release_ns) const noexcept;
  /// What wakes this aperiodic task, as its module declared in init (empty for periodic ones).
  [[nodiscard]] const Trigger& trigger() const noexcept { return trigger_; }
  /// The global index of the variable whose updates wake it (its trigger's update port), -1 for
  /// none; fixed at spawn. Real-time safe.
  [[nodiscard]] int trigger_var() const noexcept { return trigger_var_; }
  /// Real clock: how exec times are measured (set before spawn).
  void set_exec_clock(ExecClock clock) noexcept { exec_clock_ = clock; }
  /// Marks the subsystem's clock as virtual in the timing modules see (set before spawn).
  void set_virtual_clock(bool is_virtual) noexcept { virtual_clock_ = is_virtual; }
  /// Whether spawn publishes what init produced (false for a task created in the background of a
  /// running configuration, which may hold other producers of its outputs). Set before spawn.
  void set_publish_at_spawn(bool publish) noexcept { publish_at_spawn_ = publish; }
  /// --rt-check: count what on(), cycle(), off() and sync() do that the real-time path must not
  /// (set before spawn). Off, the methods run as they always do, behind one branch.
  void set_rt_check(bool on) noexcept { rt_check_ = on; }
  /// An allocation while one of its real-time methods ran on this thread (the allocator hook
  /// calls it): counted; the first also tells the operator which method. Real-time safe.
  void note_rt_allocation() noexcept;
  /// The flight recorder (docs/flight-recorder.md): each cycle's CycleRecord goes to ring
  /// `timing_ring` of `rings`, and each output variable v's value to ring `ring_of_var[v]` (-1:
  /// none). The rings and the span outlive the task. Before spawn; not real-time safe.
  void keep_history(HistoryRings* rings, std::int32_t timing_ring, std::span<const std::int32_t> ring_of_var) noexcept;
  /// Where its module's switch requests go, and its index there (set before spawn).
  void set_request_board(RequestBoard* board, int index) noexcept { services_ = {board, index}; }

  [[nodiscard]] const TaskStats& stats() const { return shared_->stats; }
  /// The executive gave up waiting for a same-rate producer. Real-time safe.
  void record_order_timeout() noexcept { shared_->stats.record_order_timeout(); }
  [[nodiscard]] EventRing<kEventCapacity>& events() { return shared_->events; }
  /// Whether this task has entered ERROR at least once. Any thread.
  [[nodiscard]] bool ever_in_error() const noexcept {
    return shared_->ever_in_error.load(std::memory_order_relaxed);  // a latch, read on its own
  }

  /// The main process's view of a task whose module process has died (docs/processes.md): a task
  /// that existed goes to ERROR (holding the flag, as every task in ERROR does) with an event
  /// giving `reason`; one already in ERROR keeps its hold. Only once the dead process can no longer
  /// write the task's shared state, from the one thread that handles the death. Not real-time safe.
  void lose_process(const char* reason, std::int64_t now_ns) noexcept;
  /// The real executive's stuck-task watch, main process only (docs/processes.md): gives up the
  /// module method this task's thread has been inside since `since_ns` (its heartbeat), if it
  /// still is: cycle(), a signal's method (init, on, off, kill, clear), reinit, or error() after a
  /// failed cycle. The task is ERROR then (holding the flag) with an event giving `reason`, and
  /// its thread, whenever the method returns, leaves it alone (given_up()). False when that
  /// method has returned meanwhile. The watch's thread; not real-time safe.
  bool give_up(std::int64_t since_ns, const char* reason, std::int64_t now_ns) noexcept;
  /// On the task's thread, after a method: it was given up while it ran, and this thread must
  /// touch neither the task nor its thread-mates again.
  [[nodiscard]] bool given_up() const noexcept { return given_up_; }
  /// What its same-period successors read of it, in any process. Real-time safe.
  [[nodiscard]] TaskPrecedence& precedence() noexcept { return shared_->precedence; }
  /// Its aperiodic trigger's state, where its producers in any process find it. Real-time safe.
  [[nodiscard]] TaskWake& wake() noexcept { return shared_->wake; }
  /// The job this task's thread is running: its absolute deadline (subsystem clock), or kNoJob.
  /// Set around each job by the task's thread; read by the overrun watch. Real-time safe.
  void set_running_deadline(std::int64_t deadline_ns) noexcept {
    // Relaxed: a status word on its own; the watch only compares it with the clock.
    shared_->running_deadline_ns.store(deadline_ns, std::memory_order_relaxed);
  }
  [[nodiscard]] std::optional<std::int64_t> running_deadline() const noexcept {
    const std::int64_t deadline = shared_->running_deadline_ns.load(std::memory_order_relaxed);  // relaxed: as above
    if (deadline == TaskShared::kNoJob) return std::nullopt;
    return deadline;
  }
  /// The heartbeat as it stands: the method the task's thread is inside and since when (subsystem
  /// clock), if any. Any thread.
  struct Busy {
    BusyIn method;
    std::int64_t since_ns;
  };
  [[nodiscard]] std::optional<Busy> busy() const noexcept {
    const std::int64_t since = shared_->busy_since_ns.load(std::memory_order_acquire);  // acquire: pairs with BusyScope
    if (since <= TaskShared::kGivenUp) return std::nullopt;
    return Busy{shared_->busy_in.load(std::memory_order_relaxed), since};  // ordered by the acquire above
  }
  /// Before its process starts again: the task is NOT CREATED (its hold on the flag given back),
  /// ready to be spawned by the new process. Returns whether it existed. Not real-time safe.
  bool forget_lost_process() noexcept;
  /// Timing seen by the module through InitContext::timing().
  [[nodiscard]] const CycleTiming& timing() const { return timing_; }

 private:
  enum class Hook : std::uint8_t { kOn, kCycle, kOff, kKill, kError, kClear, kReinit, kSync };

  Result<void> spawn(std::int64_t now_ns);
  Result<void> turn_on(std::int64_t now_ns);
  Result<void> turn_off(std::int64_t now_ns);
  Result<void> kill(std::int64_t now_ns);
  Result<void> clear(std::int64_t now_ns);

  /// Calls a hook with in-vars pulled before and out-vars pushed after; an exception becomes a
  /// failed Status whose reason lives in exception_text_. Real-time safe for the framework.
  Status call(Hook hook) noexcept;
  Status call_raw(Hook hook) noexcept;
  /// After a module method returned inside method_scope_: whether the stuck-task watch gave the
  /// task up meanwhile (then given_up(), and nothing of the task is this thread's any more).
  /// Otherwise the heartbeat goes on under a stamp no give-up aimed at that method can match.
  bool given_up_meanwhile() noexcept;
  /// The reply to a signal whose method was given up.
  [[nodiscard]] Error given_up_error() const;
  Status dispatch(Hook hook) noexcept;
  /// The paper's error rule after `hook` failed with `failure`: error() may recover (true);
  /// otherwise the task enters ERROR (false). Real-time safe.
  bool recover(Hook hook, Status failure, std::int64_t now_ns) noexcept;
  /// The same rule for a timing failure the framework detected. Real-time safe.
  void timing_fault(Fault fault, std::int64_t now_ns) noexcept;
  [[nodiscard]] std::int64_t exec_clock_now() const noexcept;
  void set_state(TaskState s) noexcept;
  void destroy_module() noexcept;

  TaskSpec spec_;
  ResolvedTask resolved_;
  GlobalTable& table_;
  const SubsystemFlags& flags_;

  std::unique_ptr<Module> module_;
  std::unique_ptr<LocalTable> local_;
  CycleTiming timing_;
  Trigger trigger_;
  int trigger_var_ = -1;
  TaskServices services_;
  ExecClock exec_clock_ = ExecClock::kWall;
  bool virtual_clock_ = false;
  bool publish_at_spawn_ = true;
  bool rt_check_ = false;
  HistoryRings* history_ = nullptr;  // the flight recorder's rings, or none
  std::int32_t timing_ring_ = -1;
  std::span<const std::int32_t> ring_of_var_;
  Hook rt_hook_ = Hook::kCycle;  // the real-time method running under --rt-check, for the event
  struct Job {
    bool open = false;
    bool failed = false;          // the error path already ran (and published)
    std::int64_t release_ns = 0;  // subsystem clock
    std::int64_t start_ns = 0;    // subsystem clock
    std::int64_t exec_start = 0;  // on exec_clock_
  } job_;
  bool given_up_ = false;              // the task's thread's: see given_up()
  BusyScope* method_scope_ = nullptr;  // the heartbeat of the signal or reinit under way, for call()
  std::uint64_t timing_faults_ = 0;    // recovered ones too: events are sent at 1, 2, 4, 8...
  std::atomic<std::uint64_t> reinits_{0};
  std::array<char, 160> exception_text_{};

  std::unique_ptr<TaskShared> own_shared_;  // when `shared` was not given
  TaskShared* shared_;
};

}  // namespace chimera
