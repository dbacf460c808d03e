#pragma once
// The task block (docs/processes.md): one TaskShared slot per task of the file, in a memfd that
// the main process creates before it starts any module process and that every worker inherits.
// A header holds the layout's fingerprint and the executive's epoch, so that a worker's periodic
// releases fall on the main process's grid. Offsets only: a slot is found at a fixed offset from
// the start, whatever address the block is mapped at. A memfd has no name, so a run however it
// ends leaves nothing of it behind. Exported to the parts above. Not real-time safe (the slots
// themselves are).

#include <pthread.h>

#include <cstddef>
#include <cstdint>

#include "chimera/core/result.hpp"
#include "doorbell.hpp"
#include "task_shared.hpp"

namespace chimera {

class TaskBlock {
 public:
  /// A new block of `tasks` slots, each as a task that was never created.
  static Result<TaskBlock> create(std::size_t tasks);
  /// Maps the block open as `fd` (inherited from the main process), checking its layout and that
  /// it has `tasks` slots. The block keeps `fd` and closes it when destroyed.
  static Result<TaskBlock> attach(int fd, std::size_t tasks);

  TaskBlock(TaskBlock&& other) noexcept;
  TaskBlock& operator=(TaskBlock&& other) noexcept;
  TaskBlock(const TaskBlock&) = delete;
  TaskBlock& operator=(const TaskBlock&) = delete;
  ~TaskBlock();

  /// The memfd, for a worker to inherit (it is close-on-exec: the launcher clears that in the child).
  [[nodiscard]] int fd() const noexcept { return fd_; }
  [[nodiscard]] std::size_t tasks() const noexcept { return tasks_; }
  [[nodiscard]] TaskShared* slot(std::size_t task) const noexcept;
  /// CLOCK_MONOTONIC at the executive's time 0, as the main process set it (0: not yet).
  [[nodiscard]] std::int64_t epoch_ns() const noexcept;
  void set_epoch_ns(std::int64_t epoch_ns) noexcept;
  /// Module process `process`'s life lock (docs/processes.md, "Seeing a death at once"): a
  /// robust, process-shared mutex its worker holds for as long as it lives. The kernel releases
  /// it as the worker's threads exit, before it frees the worker's memory, so a waiter in the
  /// main process learns of the death long before the pidfd does. One per possible process.
  [[nodiscard]] pthread_mutex_t* life(std::size_t process) const noexcept;
  /// The bell of the subsystem's switch requests (the slots are TaskShared::switch_request): a
  /// module process's task rings it, the main process's service thread sleeps on it.
  [[nodiscard]] Doorbell& requests_bell() const noexcept;

 private:
  TaskBlock() = default;
  void release() noexcept;

  std::byte* base_ = nullptr;
  std::size_t bytes_ = 0;
  std::size_t tasks_ = 0;
  int fd_ = -1;
};

}  // namespace chimera
