#pragma once
// A fixed-size single-producer single-consumer ring of events: how a real-time thread tells the
// subsystem interface that something happened (a task entered ERROR, say) without allocating,
// locking or formatting. A non-real-time thread drains it.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace chimera {

struct RtEvent {
  std::int64_t time_ns = 0;
  std::array<char, 152> text{};  // NUL-terminated, truncated if longer
};

template <std::size_t N>
class EventRing {
  static_assert((N & (N - 1)) == 0, "N must be a power of two");

 public:
  /// Appends the concatenation "<a><b><c>" (any may be null) as one event; drops the event and
  /// counts it if the ring is full. Real-time safe: no allocation, no lock, no formatting.
  void push(std::int64_t time_ns, const char* a, const char* b = nullptr, const char* c = nullptr) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);  // only this thread writes head
    // acquire: the consumer's reads of the slot we are about to reuse happened before its tail store
    if (head - tail_.load(std::memory_order_acquire) >= N) {
      dropped_.fetch_add(1, std::memory_order_relaxed);  // a counter, no ordering needed
      return;
    }
    RtEvent& e = slots_[head & (N - 1)];
    e.time_ns = time_ns;
    std::size_t n = 0;
    for (const char* s : {a, b, c}) {
      for (; s != nullptr && *s != '\0' && n + 1 < e.text.size(); ++s) e.text[n++] = *s;
    }
    e.text[n] = '\0';
    head_.store(head + 1, std::memory_order_release);  // release: publishes the slot's contents
  }

  /// Removes the oldest event into `out`; false if there is none. Consumer side only.
  bool pop(RtEvent& out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);  // only the consumer writes tail
    if (tail == head_.load(std::memory_order_acquire)) return false;   // acquire: see the slot's contents
    out = slots_[tail & (N - 1)];
    tail_.store(tail + 1, std::memory_order_release);  // release: our read of the slot is done
    return true;
  }

  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  alignas(64) std::atomic<std::uint64_t> head_{0};
  alignas(64) std::atomic<std::uint64_t> tail_{0};
  alignas(64) std::atomic<std::uint64_t> dropped_{0};
  std::array<RtEvent, N> slots_{};
};

}  // namespace chimera
