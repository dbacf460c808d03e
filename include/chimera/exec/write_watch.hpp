#pragma once
// Wakes one thread outside the executive (the DDS bridge's publisher) when a task of this process
// publishes a variable it watches, so that the thread need not poll the table: Subsystem::
// watch_writes(). The producer's side is real-time safe and costs a system call only when the
// watcher has taken the news before (one eventfd write a wake, however many tasks publish).

#include <atomic>

namespace chimera {

class WriteWatch {
 public:
  /// Makes its eventfd (non-blocking, close-on-exec); fd() < 0 if the system refused one, and then
  /// written() does nothing but note the news. Not real-time safe.
  WriteWatch();
  ~WriteWatch();
  WriteWatch(const WriteWatch&) = delete;
  WriteWatch& operator=(const WriteWatch&) = delete;
  WriteWatch(WriteWatch&&) = delete;
  WriteWatch& operator=(WriteWatch&&) = delete;

  /// Readable (POLLIN) while there is news the watcher has not taken.
  [[nodiscard]] int fd() const noexcept { return fd_; }
  /// A watched variable was published (after its value, by the table's own protocol). Real-time
  /// safe: one atomic exchange, and one eventfd write when the news is the first since the last
  /// take(). Any thread.
  void written() noexcept;
  /// The watcher's, before it reads the watched variables: takes the news, whether there was any.
  /// A value published before a written() that take() consumed is visible to reads after it.
  bool take() noexcept;

 private:
  int fd_ = -1;
  alignas(64) std::atomic<bool> pending_{false};
};

}  // namespace chimera
