#pragma once
// One task's thread on the real clock: its mailbox for signals, its releases (periodic timer or
// aperiodic trigger), the same-rate precedence wait, its sporadic server and, under EDF or MUF,
// the job it publishes for its CPU's priority dispatcher. Private to the real executive.

#include <pthread.h>
#include <sched.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "chimera/exec/task.hpp"
#include "urgency.hpp"

namespace chimera {

class RealExecutive;
class PriorityDispatcher;

/// What the control thread asks of a task's thread.
enum class MailKind : std::uint8_t {
  kSignal,   // carry out `signal` (the paper's signals)
  kOnHeld,   // turn on, but release nothing until kJoin: tasks that start together
  kJoin,     // first release at index `at`, set by the control thread for every task of a group
  kLeaveAt,  // turn off before the first release at or after absolute time `at`; reply once off
  kReinit,   // an in-const changed: reinit() between two cycles
};

struct Mail {
  MailKind kind = MailKind::kSignal;
  Signal signal = Signal::kSpawn;
  std::int64_t at = 0;
};

struct Worker {
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
  int bell_fd = -1;                          // aperiodic: eventfd rung by signals and producers
  pthread_t thread{};                        // the control thread's handle (join)
  bool running = false;                      // the control thread's view: a thread exists

  // Mailbox: written by the control thread, read by the task's thread.
  alignas(64) std::atomic<std::uint32_t> request_seq{0};
  Mail mail;
  // Reply: written by the task's thread, read by the control thread.
  alignas(64) std::atomic<std::uint32_t> done_seq{0};
  Result<void> reply;

  // Precedence: the last release completed (+1, modulo 2^32), and how many successors sleep on it.
  alignas(64) std::atomic<std::uint32_t> completed{0};
  std::atomic<std::uint32_t> waiters{0};
  std::atomic<std::int64_t> scheduled{-1};  // release index about to run; -1 when not released

  // The job it publishes for its dispatcher (edf / muf), and its own thread handle for it.
  alignas(64) std::atomic<bool> job_active{false};
  std::atomic<std::int64_t> job_release_ns{0};
  std::atomic<std::int64_t> job_deadline_ns{0};
  std::atomic<pthread_t> self{};
  std::atomic<int> current_priority{0};  // what it runs at (set by itself or its dispatcher)

  // Aperiodic triggers: the variable it waits on (-1: none), and an update not yet served.
  alignas(64) std::atomic<int> trigger_var{-1};
  std::atomic<bool> update_pending{false};

  // Group starts and switches: touched only by the task's own thread.
  bool held = false;            // ON, but waiting for kJoin before its first release
  std::int64_t leave_at = -1;   // absolute time: turn off before the first release at or after it
  std::uint32_t leave_seq = 0;  // the kLeaveAt request to answer once off (0: none)

  // Sporadic server: touched only by the task's own thread.
  static constexpr std::size_t kMaxRefills = 64;
  std::int64_t budget_ns = 0;
  std::array<std::pair<std::int64_t, std::int64_t>, kMaxRefills> refills{};  // (abs time, amount) ring
  std::size_t refill_head = 0;
  std::size_t refill_count = 0;

  Worker() = default;
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;
  ~Worker();

  /// The thread's body: from spawn until the task is killed (or its init fails).
  void main();

 private:
  bool handle(std::uint32_t seq, std::int64_t& k);
  void reply_to(std::uint32_t seq);
  /// Turns off now for a pending kLeaveAt, and answers it.
  void leave();
  void run_periodic(std::uint32_t seq, std::int64_t& k);
  void run_aperiodic(std::uint32_t seq);
  void wait_for_predecessors(std::int64_t k, std::int64_t release_abs) const;
  /// Runs one job and tells successors and subscribers; returns the execution time it used.
  std::int64_t run_job(std::int64_t release_abs);
  void publish_job(std::int64_t release_abs);
  void refill(std::int64_t now_abs) noexcept;
  void on_turned_on() noexcept;
};

}  // namespace chimera
