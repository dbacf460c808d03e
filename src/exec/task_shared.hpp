#pragma once
// What of a task the other processes of a subsystem see (docs/processes.md): its lifecycle state,
// its timing statistics, its real-time event ring and its ever-in-ERROR latch. A task of the main
// process keeps them in its own memory; a task whose module runs in a module process keeps them in
// the task block (task_block.hpp), shared memory that both the worker running the task and the main
// process's view of it map. Every member is a lock-free atomic or a fixed array of them, and holds
// no pointer, so that it means the same at any address in any process. Private to the exec part
// and the parts above.

#include <atomic>
#include <cstdint>
#include <limits>
#include <optional>

#include "chimera/exec/stats.hpp"
#include "chimera/lifecycle/state.hpp"
#include "event_ring.hpp"

namespace chimera {

/// The module method a task's thread is inside (its heartbeat, below). kError: error() after a
/// failed cycle().
enum class BusyIn : std::uint8_t { kInit, kOn, kCycle, kOff, kKill, kClear, kReinit, kError };

/// The method's name as the module's author wrote it ("cycle").
const char* busy_in_name(BusyIn method) noexcept;

/// What wakes an aperiodic task on an update of a variable (Trigger::update_port): the variable it
/// waits on (-1: none) and an update not yet served. Written by its producers' threads, in any
/// process, so it has a cache line of its own.
struct TaskWake {
  alignas(64) std::atomic<int> trigger_var{-1};
  std::atomic<bool> update_pending{false};
};

/// What same-period successors read of a task (the same-rate rule, docs/architecture.md), written
/// by its thread and read, and slept on, by theirs: in the task block with module processes, so
/// that a successor in another process waits for it as one of its own process does.
struct TaskPrecedence {
  // The last release completed (+1, modulo 2^32), and how many successors sleep on it. A
  // successor of a process that died asleep leaves its count behind: its producer then makes one
  // futex wake too many a cycle, never one too few.
  alignas(64) std::atomic<std::uint32_t> completed{0};
  std::atomic<std::uint32_t> waiters{0};
  std::atomic<std::int64_t> scheduled{-1};  // release index about to run; -1 when not released
  // A switch's commit: the release this (still OFF) task will join at; -1 when none. Successors
  // wait for it at that release as if it were ON, so that a commit running late cannot make them
  // read the leaving producer's last value.
  std::atomic<std::int64_t> joining_k{-1};
};

struct TaskShared {
  static constexpr std::size_t kEventCapacity = 64;
  static constexpr std::int64_t kIdle = std::numeric_limits<std::int64_t>::min();
  /// The stamp of a method the stuck-task watch gave up (Task::give_up): its thread finds it when
  /// the method returns, and from then on leaves the task alone.
  static constexpr std::int64_t kGivenUp = kIdle + 1;

  alignas(64) std::atomic<TaskState> state{TaskState::kNotCreated};
  std::atomic<bool> ever_in_error{false};
  /// The heartbeat (docs/processes.md): since when (subsystem clock) the task's thread has been
  /// inside a module method, and which; kIdle between methods. The supervisor kills a module
  /// process whose task stays too long in one; the main process's own stuck cycles are given up.
  std::atomic<std::int64_t> busy_since_ns{kIdle};
  std::atomic<BusyIn> busy_in{BusyIn::kCycle};
  /// The job the task's thread is running, for the overrun watch (service_thread.cpp), which the
  /// main process runs over every task, a module process's too: its absolute deadline (subsystem
  /// clock), which names the job; kNoJob while none runs.
  static constexpr std::int64_t kNoJob = std::numeric_limits<std::int64_t>::max();
  std::atomic<std::int64_t> running_deadline_ns{kNoJob};
  /// The configuration the task's module asks for (index in the file, -1: none), where the file
  /// has module processes: the request board's slot (reconfig/request_board.hpp), shared so that a
  /// module process's task can ask. Written by the task's thread, cleared by the service thread.
  std::atomic<int> switch_request{-1};
  TaskWake wake;
  TaskPrecedence precedence;
  TaskStats stats;
  EventRing<kEventCapacity> events;
};

static_assert(std::atomic<TaskState>::is_always_lock_free, "a task's state is shared between processes");
static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "statistics are shared between processes");
static_assert(std::atomic<std::int64_t>::is_always_lock_free, "the heartbeat is shared between processes");

/// How long a task may stay inside one module method before it is taken for stuck: in cycle(),
/// ten of its periods or deadlines, whichever is longer, and at least 200 ms (3 s in a sanitized
/// build, which takes far longer over everything); in any other method, 10 s.
struct StuckBound {
  static constexpr std::int64_t kPeriods = 10;
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  static constexpr std::int64_t kCycleFloorNs = 3'000'000'000;
#else
  static constexpr std::int64_t kCycleFloorNs = 200'000'000;
#endif
  static constexpr std::int64_t kMethodNs = 10'000'000'000;
  [[nodiscard]] static constexpr std::int64_t of(BusyIn method, std::int64_t period_ns, std::int64_t deadline_ns) {
    if (method != BusyIn::kCycle) return kMethodNs;
    const std::int64_t span = period_ns > deadline_ns ? period_ns : deadline_ns;
    return kPeriods * span > kCycleFloorNs ? kPeriods * span : kCycleFloorNs;
  }
};

/// Stamps the heartbeat for the scope of one module method. Real-time safe: a few stores.
class BusyScope {
 public:
  BusyScope(TaskShared& shared, BusyIn method, std::int64_t now_ns) noexcept
      : shared_(shared), since_(now_ns), method_(method) {
    shared_.busy_in.store(method, std::memory_order_relaxed);        // published by the release below
    shared_.busy_since_ns.store(now_ns, std::memory_order_release);  // release: the method is read with it
  }
  ~BusyScope() {
    if (open_)
      shared_.busy_since_ns.store(TaskShared::kIdle, std::memory_order_release);  // release: ordered after the method
  }
  BusyScope(const BusyScope&) = delete;
  BusyScope& operator=(const BusyScope&) = delete;

  /// The method has returned. True when the stuck-task watch gave it up while it ran: the task is
  /// the watch's then, and this thread must leave it alone. With `then`, the stamp goes on as that
  /// method (error() after a failed cycle) under a value of its own, which no give-up aimed at the
  /// method that returned can match.
  [[nodiscard]] bool returned(std::optional<BusyIn> then = std::nullopt) noexcept {
    open_ = then.has_value();
    if (then) {
      method_ = *then;
      shared_.busy_in.store(*then, std::memory_order_relaxed);  // published by the exchange below
    }
    // acq_rel: release orders the method (and `then`) before the new stamp; acquire pairs with the
    // watch's give-up, so that this thread sees the ERROR it set before leaving the task alone.
    const std::int64_t was =
        shared_.busy_since_ns.exchange(then ? since_ + 1 : TaskShared::kIdle, std::memory_order_acq_rel);
    return was == TaskShared::kGivenUp;
  }
  /// The method the stamp names now.
  [[nodiscard]] BusyIn method() const noexcept { return method_; }

 private:
  TaskShared& shared_;
  std::int64_t since_;
  BusyIn method_;
  bool open_ = true;
};

}  // namespace chimera
