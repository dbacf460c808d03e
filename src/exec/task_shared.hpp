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

#include "chimera/exec/stats.hpp"
#include "chimera/lifecycle/state.hpp"
#include "event_ring.hpp"

namespace chimera {

struct TaskShared {
  static constexpr std::size_t kEventCapacity = 64;

  alignas(64) std::atomic<TaskState> state{TaskState::kNotCreated};
  std::atomic<bool> ever_in_error{false};
  TaskStats stats;
  EventRing<kEventCapacity> events;
};

static_assert(std::atomic<TaskState>::is_always_lock_free, "a task's state is shared between processes");
static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "statistics are shared between processes");

}  // namespace chimera
