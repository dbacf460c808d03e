// The flight recorder's rings: the newest records kept, oldest first, and never a torn record
// while a writer laps the reader.

#include "chimera/core/history_rings.hpp"

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include <gtest/gtest.h>

#if CHIMERA_ALLOCATION_GUARD
#include "support/allocation_guard.hpp"
#endif

namespace chimera {
namespace {

TEST(HistoryRings, KeepsTheNewestRecordsOldestFirst) {
  HistoryRings rings;
  const std::size_t small = rings.add(4, 12);  // 12 bytes: a record's last word only half used
  const std::size_t other = rings.add(3, 8);
  rings.allocate();
  EXPECT_TRUE(rings.read(small).empty());
  for (std::uint32_t i = 1; i <= 10; ++i) {
    const std::array<std::uint32_t, 3> payload{i, 2 * i, 3 * i};
    rings.write(small, static_cast<std::int64_t>(i) * 1000, payload.data());
  }
  const std::uint64_t one = 42;
  rings.write(other, 5, &one);
  EXPECT_EQ(rings.written(small), 10U);
  const auto held = rings.read(small);
  ASSERT_EQ(held.size(), 4U);  // records 7 to 10
  for (std::size_t k = 0; k < held.size(); ++k) {
    const auto i = static_cast<std::uint32_t>(7 + k);
    EXPECT_EQ(held[k].time_ns, static_cast<std::int64_t>(i) * 1000);
    ASSERT_EQ(held[k].words.size(), 2U);
    EXPECT_EQ(held[k].words[0], (std::uint64_t{2 * i} << 32) | i);
    EXPECT_EQ(held[k].words[1] & 0xffffffffU, 3 * i);
    EXPECT_EQ(held[k].words[1] >> 32, 0U);  // the unused half stays zero
  }
  const auto others = rings.read(other);  // a ring beside it is untouched by the first
  ASSERT_EQ(others.size(), 1U);
  EXPECT_EQ(others[0].words[0], 42U);
}

// Every record's words are its time repeated: a torn copy would mix two times.
TEST(HistoryRings, AReaderNeverSeesATornRecordWhileTheWriterLapsIt) {
  HistoryRings rings;
  constexpr std::uint32_t kWords = 16;
  const std::size_t r = rings.add(8, kWords * 8);
  rings.allocate();
  std::atomic<bool> done{false};
  std::thread writer([&] {
    std::array<std::uint64_t, kWords> payload{};
    for (std::int64_t t = 1; t <= 400'000; ++t) {
      payload.fill(static_cast<std::uint64_t>(t));
      rings.write(r, t, payload.data());
    }
    done.store(true, std::memory_order_release);  // release: the last write before the flag
  });
  std::uint64_t copies = 0;
  while (!done.load(std::memory_order_acquire)) {  // acquire: pairs with the writer's release
    const auto held = rings.read(r);
    std::int64_t previous = 0;
    for (const auto& record : held) {
      for (const std::uint64_t w : record.words) ASSERT_EQ(w, static_cast<std::uint64_t>(record.time_ns));
      ASSERT_GT(record.time_ns, previous);  // oldest first
      previous = record.time_ns;
      ++copies;
    }
    // A reader lapped by the writer leaves out what was overwritten as it copied: at most the
    // ring's capacity, never more.
    EXPECT_LE(held.size(), 8U);
  }
  writer.join();
  const auto final_records = rings.read(r);
  ASSERT_EQ(final_records.size(), 8U);
  EXPECT_EQ(final_records.back().time_ns, 400'000);
  EXPECT_GT(copies, 0U);
}

#if CHIMERA_ALLOCATION_GUARD  // plain builds: a sanitizer brings its own allocator
// A copy of ten thousand records is two allocations (times, words), not one per record: with
// locked memory, freed small blocks stayed in the heap, and a run's first dump grew it for good.
TEST(HistoryRings, ACopyOfTenThousandRecordsIsTwoAllocations) {
  HistoryRings rings;
  const std::size_t r = rings.add(10'000, 6 * 8);
  rings.allocate();
  const std::array<double, 6> payload{1, 2, 3, 4, 5, 6};
  for (std::int64_t t = 1; t <= 12'000; ++t) rings.write(r, t, payload.data());
  long allocations = 0;
  HistoryRings::Records held;
  {
    const testing::AllocationGuard guard;
    held = rings.read(r);
    allocations = testing::AllocationGuard::count();
  }
  ASSERT_EQ(held.size(), 10'000U);
  EXPECT_EQ(held[0].time_ns, 2'001);
  EXPECT_EQ(held.back().time_ns, 12'000);
  EXPECT_EQ(held[0].words.size(), 6U);
  EXPECT_LE(allocations, 2);
}
#endif

}  // namespace
}  // namespace chimera
