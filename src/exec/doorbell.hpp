#pragma once
// A word that changes each time someone has news, and that a thread can sleep on until it does
// (a Linux futex underneath): how a module's switch request reaches the subsystem interface, and
// how the real executive's service thread waits for it. Ringing is real-time safe. Process-shared:
// it holds no pointer and may live in shared memory (the task block), where a module process's
// task rings the bell the main process's service thread sleeps on.

#include <atomic>
#include <cstdint>

namespace chimera {

class Doorbell {
 public:
  /// Announces news: what the ringer wrote before is seen by whoever reads rung() after. Real-time
  /// safe (one atomic increment and one futex wake).
  void ring() noexcept;
  /// How many times it has rung (modulo 2^32); a change means news.
  [[nodiscard]] std::uint32_t rung() const noexcept {
    return word_.load(std::memory_order_acquire);  // acquire: pairs with ring()'s release
  }
  /// Sleeps while rung() is still `seen`, until the absolute CLOCK_MONOTONIC time `deadline_ns`
  /// (< 0: none). Returns false on timeout; may return early. Not real-time safe (it blocks).
  bool wait(std::uint32_t seen, std::int64_t deadline_ns) const noexcept;

 private:
  alignas(64) std::atomic<std::uint32_t> word_{0};
};

}  // namespace chimera
