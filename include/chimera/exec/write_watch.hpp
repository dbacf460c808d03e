#pragma once
// Wakes one thread outside the executive (the DDS bridge's publisher) when a task of this process
// publishes a variable it watches, so that the thread need not poll the table: Subsystem::
// watch_writes(). The producer's side is real-time safe and makes a system call only when the
// watcher is asleep and the news is the first since it last took it: one futex wake a sleep,
// however many tasks publish, and none while the watcher is busy publishing.

#include <atomic>
#include <cstdint>

namespace chimera {

class WriteWatch {
 public:
  WriteWatch() = default;
  WriteWatch(const WriteWatch&) = delete;
  WriteWatch& operator=(const WriteWatch&) = delete;
  WriteWatch(WriteWatch&&) = delete;
  WriteWatch& operator=(WriteWatch&&) = delete;

  /// A watched variable was published (after its value, by the table's own protocol). Real-time
  /// safe: one atomic read-modify-write, and a futex wake only when the watcher sleeps on news it
  /// has not had yet. Any thread; also the watcher's owner, to end its sleep (news of nothing).
  void written() noexcept;
  /// The watcher's, before it reads the watched variables: takes the news, whether there was any.
  /// A value published before a written() that take() consumed is visible to reads after it.
  bool take() noexcept;
  /// The watcher's: returns at once when there is news it has not taken, else sleeps until there
  /// is or until the absolute CLOCK_MONOTONIC time `deadline_ns`. It may return early (a futex's
  /// spurious wake): the watcher reads what is new either way.
  void wait_until(std::int64_t deadline_ns) noexcept;

 private:
  static constexpr std::uint32_t kNews = 1;      // written() since the last take()
  static constexpr std::uint32_t kSleeping = 2;  // the watcher is in wait_until(), or about to be
  alignas(64) std::atomic<std::uint32_t> word_{0};
};

}  // namespace chimera
