// The data logger's ring between two threads: every row the producer publishes reaches the
// consumer whole and in order, however the two interleave (run under TSAN as a concurrency test).

#include <atomic>
#include <cstdint>
#include <thread>

#include <gtest/gtest.h>

#include "data_logger/row_ring.hpp"

namespace chimera::modules {
namespace {

TEST(RowRingStress, EveryRowArrivesWholeAndInOrder) {
  constexpr std::size_t kWidth = 7;
  constexpr std::uint64_t kRows = 200'000;
  RowRing ring(64, kWidth);
  std::atomic<bool> done{false};

  std::thread producer([&] {
    for (std::uint64_t n = 0; n < kRows;) {
      double* row = ring.claim();
      if (row == nullptr) {
        std::this_thread::yield();
        continue;
      }
      for (std::size_t j = 0; j < kWidth; ++j) row[j] = static_cast<double>(n * kWidth + j);
      ring.publish();
      ++n;
    }
    done.store(true, std::memory_order_release);  // release: every publish happened before
  });

  std::uint64_t expected = 0;
  std::uint64_t torn = 0;
  auto check = [&](const double* row) {
    for (std::size_t j = 0; j < kWidth; ++j)
      if (row[j] != static_cast<double>(expected * kWidth + j)) ++torn;
    ++expected;
  };
  while (!done.load(std::memory_order_acquire)) {
    if (ring.drain(check) == 0) std::this_thread::yield();
  }
  ring.drain(check);
  producer.join();
  EXPECT_EQ(expected, kRows);
  EXPECT_EQ(torn, 0u);
}

}  // namespace
}  // namespace chimera::modules
