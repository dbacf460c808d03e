#pragma once
// A single-producer single-consumer ring of rows of doubles, allocated once: how the data logger's
// real-time cycle hands rows to the ordinary thread that writes them out. The producer never
// waits and never allocates; when the ring is full it says so and the caller decides (drop the
// row on the real clock, wait on the virtual one).

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace chimera::modules {

class RowRing {
 public:
  /// `rows` slots of `width` doubles each (both at least 1). Allocates; not real-time safe.
  RowRing(std::size_t rows, std::size_t width) : rows_(rows), width_(width), data_(rows * width, 0.0) {}

  [[nodiscard]] std::size_t rows() const noexcept { return rows_; }
  [[nodiscard]] std::size_t width() const noexcept { return width_; }

  /// Producer: the next free slot to fill, or nullptr if the ring is full. Call publish() after
  /// filling it. Real-time safe.
  [[nodiscard]] double* claim() noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);  // only the producer writes head
    // acquire: the consumer has finished reading the slot we are about to reuse
    if (head - tail_.load(std::memory_order_acquire) >= rows_) return nullptr;
    return &data_[(head % rows_) * width_];
  }
  /// Producer: makes the claimed slot visible to the consumer. Real-time safe.
  void publish() noexcept {
    // release: the slot's contents are written before the consumer can see the new head
    head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  /// Consumer: calls `f(const double* row)` for every published row, oldest first, then frees
  /// their slots. Returns how many rows it read.
  template <class F>
  std::size_t drain(F&& f) {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);  // only the consumer writes tail
    const std::uint64_t head = head_.load(std::memory_order_acquire);  // acquire: pairs with publish()
    for (std::uint64_t i = tail; i != head; ++i) f(&data_[(i % rows_) * width_]);
    tail_.store(head, std::memory_order_release);  // release: our reads are done before the slots are reused
    return static_cast<std::size_t>(head - tail);
  }

 private:
  // Each index is written by one side only and gets its own cache line, so that the producer's
  // and the consumer's stores do not share one.
  static constexpr std::size_t kLine = 64;
  alignas(kLine) std::atomic<std::uint64_t> head_{0};
  alignas(kLine) std::atomic<std::uint64_t> tail_{0};
  alignas(kLine) std::size_t rows_;
  std::size_t width_;
  std::vector<double> data_;
};

}  // namespace chimera::modules
