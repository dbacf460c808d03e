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

#include "chimera/exec/stats.hpp"
#include "chimera/lifecycle/state.hpp"
#include "event_ring.hpp"

namespace chimera {

/// The module method a task's thread is inside (its heartbeat, below).
enum class BusyIn : std::uint8_t { kInit, kOn, kCycle, kOff, kKill, kClear, kReinit };

/// The method's name as the module's author wrote it ("cycle").
const char* busy_in_name(BusyIn method) noexcept;

struct TaskShared {
  static constexpr std::size_t kEventCapacity = 64;
  static constexpr std::int64_t kIdle = std::numeric_limits<std::int64_t>::min();

  alignas(64) std::atomic<TaskState> state{TaskState::kNotCreated};
  std::atomic<bool> ever_in_error{false};
  /// The heartbeat (docs/processes.md): since when (subsystem clock) the task's thread has been
  /// inside a module method, and which; kIdle between methods. The supervisor kills a module
  /// process whose task stays too long in one.
  std::atomic<std::int64_t> busy_since_ns{kIdle};
  std::atomic<BusyIn> busy_in{BusyIn::kCycle};
  TaskStats stats;
  EventRing<kEventCapacity> events;
};

static_assert(std::atomic<TaskState>::is_always_lock_free, "a task's state is shared between processes");
static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "statistics are shared between processes");
static_assert(std::atomic<std::int64_t>::is_always_lock_free, "the heartbeat is shared between processes");

/// Stamps the heartbeat for the scope of one module method. Real-time safe: three stores.
class BusyScope {
 public:
  BusyScope(TaskShared& shared, BusyIn method, std::int64_t now_ns) noexcept : shared_(shared) {
    shared_.busy_in.store(method, std::memory_order_relaxed);  // published by the release below
    shared_.busy_since_ns.store(now_ns, std::memory_order_release);  // release: the method is read with it
  }
  ~BusyScope() { shared_.busy_since_ns.store(TaskShared::kIdle, std::memory_order_release); }  // release: ordered after the method
  BusyScope(const BusyScope&) = delete;
  BusyScope& operator=(const BusyScope&) = delete;

 private:
  TaskShared& shared_;
};

}  // namespace chimera
