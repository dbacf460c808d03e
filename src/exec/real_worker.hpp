#pragma once
// The real clock's threads and the tasks they run. A Worker is one task's side: its mailbox for
// signals, its releases (periodic grid or aperiodic trigger), the same-rate precedence wait, its
// sporadic server and, under EDF or MUF, the job it publishes for its CPU's priority dispatcher.
// A TaskThread runs one task, or under rm and dm the periodic tasks that share a CPU, a period
// and so a priority: SCHED_FIFO would run such threads one after the other, never preempting
// each other, so one thread running them in data-flow order behaves the same with one wake-up
// instead of many. Private to the real executive.
//
// A Worker's state is grouped by who writes it: fixed at construction; the mailbox (control
// thread in, task's thread out); what successors, the dispatcher, the overrun watch and
// producers read of it (each group on its own cache line); and what only its thread touches.

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <cstdint>
#include <limits>
#include <vector>

#include "futex.hpp"
#include "sporadic_server.hpp"
#include "task.hpp"
#include "urgency.hpp"

namespace chimera {

class RealExecutive;
class PriorityDispatcher;
struct Worker;

/// One thread and the tasks it runs (in data-flow order).
struct TaskThread {
  std::vector<Worker*> members;
  int number = 0;  // from 1, in the order the threads were made: its members' `group`
  int cpu = 0;
  int priority = 1;
  pthread_t handle{};    // the control thread's: for join
  bool running = false;  // the control thread's view: the thread exists
  // Rung by every mail to a member: the thread sleeps on this one word whatever it waits for.
  alignas(64) std::atomic<std::uint32_t> bell{0};
  int alive = 0;                     // members spawned and not killed; the thread's own count
  std::atomic<bool> exiting{false};  // set before the answer to the mail that killed its last member
  bool unanswered = false;           // the control thread's: a mail went unanswered (a method is stuck)
  bool left_behind = false;          // the control thread's: shutdown() gave up joining it
  bool given_up = false;             // the control thread's: stuck in a member's method, its other members moved

  /// The body: until no member is alive.
  void main();

 private:
  void run_periodic_members();
  // How early to wake for the next release (release_policy::wake_lead): by its first member ON.
  [[nodiscard]] std::int64_t wake_lead() const noexcept;
};

/// What the control thread asks of a task's thread.
enum class MailKind : std::uint8_t {
  kSignal,   // carry out `signal` (the paper's signals)
  kOnHeld,   // turn on, but release nothing until kJoin: tasks that start together
  kJoin,     // first release at index `at`, set by the control thread for every task of a group
  kLeaveAt,  // turn off before the first release at or after absolute time `at`; reply once off
  kReinit,   // an in-const changed: reinit() between two cycles
  kOnAt,     // a switch: turn on right before release index `at` and run it; reply once on
};

struct Mail {
  MailKind kind = MailKind::kSignal;
  Signal signal = Signal::kSpawn;
  std::int64_t at = 0;
};

struct Worker {
  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();
  static constexpr std::int64_t kNoRelease = std::numeric_limits<std::int64_t>::min();

  // Fixed at construction (before any thread starts).
  RealExecutive* exec = nullptr;
  Task* task = nullptr;
  std::size_t index = 0;              // the task's position in the file
  std::vector<Worker*> predecessors;  // same-period producers that run before it at a shared release
  std::vector<Worker*> subscribers;   // aperiodic tasks that read one of its out-vars
  std::vector<int> out_vars;          // global indices of its out-vars
  int cpu = 0;
  int fixed_priority = 1;                    // SCHED_FIFO priority under rm / dm (and at start)
  PriorityDispatcher* dispatcher = nullptr;  // edf / muf: who ranks its jobs
  int bell_fd = -1;                          // aperiodic: eventfd rung by signals and producers, in any process
  // The thread that runs it: changed only when the stuck-task watch moves it off a stuck thread,
  // under the control mutex and before the new thread starts. Other tasks' threads compare
  // `group` instead, which never changes.
  TaskThread* thread = nullptr;
  int group = -1;         // its first thread's number: tasks that share a thread, or did, in data-flow order
  bool given_up = false;  // the control thread's view (under the control mutex): its method was given up
  BusyIn given_up_in = BusyIn::kCycle;  // which method that was, under the same mutex

  /// Requests from the control thread and the answers of the task's thread.
  struct Mailbox {
    alignas(64) std::atomic<std::uint32_t> request_seq{0};  // written by the control thread
    Mail mail;
    alignas(64) std::atomic<std::uint32_t> done_seq{0};  // written by the task's thread
    Result<void> reply;
    // kLeaveAt's answer beside `reply`: the last release it ran (executive clock), kNoRelease if
    // none. A commit posted late may find it has run the commit's release already.
    std::int64_t last_release_ns = kNoRelease;
    std::uint32_t seen = 0;  // the last mail handled; the task's thread's
  } mailbox;

  /// What same-period successors read of it (the same-rate rule): its task's, in the task block
  /// with module processes; futex waits and wakes on it are then process-shared.
  TaskPrecedence* precedence = nullptr;
  detail::FutexScope futex_scope = detail::FutexScope::kProcess;

  /// The job it publishes for its dispatcher (edf / muf), and its own thread handle for it.
  struct DispatchedJob {
    alignas(64) std::atomic<bool> active{false};
    std::atomic<std::int64_t> release_ns{0};
    std::atomic<std::int64_t> deadline_ns{0};
    std::atomic<pthread_t> self{};
    std::atomic<int> current_priority{0};  // what it runs at (set by itself or its dispatcher)
  } job;

  /// Touched only by the task's thread: its place on the grid, and a group start or a switch
  /// it is in the middle of.
  struct Schedule {
    std::int64_t k = 0;           // periodic: index of its next release on the grid
    std::int64_t last_run = -1;   // periodic: index of the last release it ran since it turned on
    bool held = false;            // ON, but waiting for kJoin before its first release
    std::int64_t leave_at = -1;   // absolute time: turn off before the first release at or after it
    std::uint32_t leave_seq = 0;  // the kLeaveAt request to answer once off (0: none)
    std::int64_t on_at = -1;      // kOnAt: the release index to turn on right before (-1: none)
    std::uint32_t on_seq = 0;     // the kOnAt request to answer once on
  } schedule;
  SporadicServer server;  // the task's thread's too

  Worker() = default;
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;
  Worker(Worker&&) = delete;
  Worker& operator=(Worker&&) = delete;
  ~Worker();

  /// Handles the mail if there is new mail. Returns false when the task has just been destroyed
  /// (killed, or its init failed). On the task's thread.
  bool take_mail();
  /// Periodic: the absolute time at which it has something to do (its next release, a pending
  /// join or leave), or kNever when nothing until mail; publishes `scheduled` for successors.
  [[nodiscard]] std::int64_t prepare();
  /// Periodic, once prepare()'s time has come: the release (late releases skipped under
  /// late: skip), or the pending join or leave. On the task's thread.
  void act();
  /// Aperiodic: waits for its trigger (or mail) and serves one event within its server's budget.
  void run_aperiodic();

 private:
  bool handle(std::uint32_t seq);
  void reply_to(std::uint32_t seq);
  /// Turns off now for a pending kLeaveAt, and answers it.
  void leave();
  /// A pending kOnAt whose release has come: turns on and answers.
  void join_now();
  void wait_for_predecessors(std::int64_t release, std::int64_t release_abs) const;
  /// Runs one job and tells successors and subscribers; returns the execution time it used.
  std::int64_t run_job(std::int64_t release_abs);
  void publish_job(std::int64_t release_abs);
  void on_turned_on() noexcept;
};

}  // namespace chimera
