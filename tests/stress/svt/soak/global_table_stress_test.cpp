// One writer as fast as it can, several readers as fast as they can: every value a reader gets
// must be whole (all elements from the same write) and versions must never go back.
// Write number k stores k in every element, so a value is whole iff all elements equal its version.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <functional>
#include <iostream>
#include <optional>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/svt/detail/seq_protocol.hpp"
#include "chimera/svt/detail/shm_layout.hpp"
#include "chimera/svt/global_table.hpp"
#include "chimera/svt/local_table.hpp"
#include "unit/svt/svt_test_support.hpp"

namespace chimera {
namespace {

using namespace std::chrono_literals;
constexpr auto kRunFor = 1s;
constexpr int kReaders = 2;

struct Counts {
  std::atomic<std::uint64_t> reads{0};
  std::atomic<std::uint64_t> news{0};
  std::atomic<std::uint64_t> torn{0};
  std::atomic<std::uint64_t> backwards{0};
  std::atomic<std::uint64_t> changed_when_old{0};
};

/// Whole iff every element equals `expected`.
bool all_equal(const std::vector<double>& v, double expected) {
  for (double x : v) {
    if (x != expected) return false;
  }
  return true;
}

void writer_loop(GlobalTable& table, VarIndex var, std::uint32_t count, const std::atomic<bool>& stop,
                 std::atomic<std::uint64_t>& writes) {
  std::vector<double> value(count);
  for (std::uint64_t k = 1; !stop.load(std::memory_order_relaxed); ++k) {
    std::fill(value.begin(), value.end(), static_cast<double>(k));
    table.write(var, value.data());
    writes.store(k, std::memory_order_relaxed);
  }
}

void reader_loop(const GlobalTable& table, VarIndex var, std::uint32_t count, const std::atomic<bool>& stop,
                 Counts& counts) {
  std::vector<double> value(count, 0.0);
  std::uint64_t seen = 0;
  std::uint64_t reads = 0;
  while (!stop.load(std::memory_order_relaxed)) {
    const ReadOutcome r = table.read(var, value.data(), seen);
    ++reads;
    switch (r.freshness) {
      case Freshness::kNew:
        counts.news.fetch_add(1, std::memory_order_relaxed);
        if (r.version <= seen) counts.backwards.fetch_add(1, std::memory_order_relaxed);
        if (!all_equal(value, static_cast<double>(r.version))) counts.torn.fetch_add(1, std::memory_order_relaxed);
        break;
      case Freshness::kOld:
        // Nothing newer, or starved by a lapping writer: either way the copy is the last whole one.
        if (r.version != seen || !all_equal(value, static_cast<double>(seen))) {
          counts.changed_when_old.fetch_add(1, std::memory_order_relaxed);
        }
        break;
      case Freshness::kNoData:
        // Before the first write; or, for variables beyond read()'s stack scratch, a starved read
        // that zeroed the copy. Either way whole zeros and version 0.
        if (r.version != 0 || !all_equal(value, 0.0)) counts.torn.fetch_add(1, std::memory_order_relaxed);
        break;
    }
    seen = r.version;
  }
  counts.reads.fetch_add(reads, std::memory_order_relaxed);
}

class StressTest : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(StressTest, EveryReadIsWholeAndVersionsNeverGoBack) {
  const std::uint32_t count = GetParam();
  const std::vector<VarSpec> vars{{"busy", {ElemType::kF64, count}}};
  auto table = GlobalTable::create(test::unique_subsystem("stress"), vars);
  ASSERT_TRUE(table) << table.error().message;
  // Readers use their own mapping, as tasks of another process would.
  auto reader_view = GlobalTable::attach(table->shm_name().substr(std::string("/chimera_").size()));
  ASSERT_TRUE(reader_view) << reader_view.error().message;

  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> writes{0};
  Counts counts;
  std::vector<std::thread> threads;
  threads.emplace_back(writer_loop, std::ref(*table), 0, count, std::cref(stop), std::ref(writes));
  for (int i = 0; i < kReaders; ++i) {
    threads.emplace_back(reader_loop, std::cref(i == 0 ? *table : *reader_view), 0, count, std::cref(stop),
                         std::ref(counts));
  }
  std::this_thread::sleep_for(kRunFor);
  stop = true;
  for (auto& t : threads) t.join();

  EXPECT_EQ(counts.torn.load(), 0U);
  EXPECT_EQ(counts.backwards.load(), 0U);
  EXPECT_EQ(counts.changed_when_old.load(), 0U);
  EXPECT_GT(writes.load(), 0U);
  EXPECT_GT(counts.reads.load(), 0U);
  EXPECT_GT(counts.news.load(), 0U);
  std::cout << "f64[" << count << "]: " << writes.load() << " writes, " << counts.reads.load() << " reads, "
            << counts.news.load() << " new\n";
}

// 1024 uses read()'s larger stack scratch; 2000 has none and copies straight into the destination.
INSTANTIATE_TEST_SUITE_P(Sizes, StressTest, ::testing::Values(1U, 6U, 8U, 9U, 36U, 1024U, 2000U));

TEST(LocalTableStress, PulledInputsAreWhole) {
  constexpr std::uint32_t kCount = 36;
  const VarShape shape{ElemType::kF64, kCount};
  const std::vector<VarSpec> vars{{"q", shape}};
  auto table = GlobalTable::create(test::unique_subsystem("localstress"), vars);
  ASSERT_TRUE(table) << table.error().message;
  const std::vector<PortBinding> ports{{"in", "q", PortKind::kInVar, shape}};

  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> writes{0};
  std::atomic<std::uint64_t> torn{0};
  std::atomic<std::uint64_t> pulls{0};
  std::thread writer(writer_loop, std::ref(*table), 0, kCount, std::cref(stop), std::ref(writes));
  std::vector<std::thread> readers;
  for (int i = 0; i < kReaders; ++i) {
    readers.emplace_back([&] {
      auto local = LocalTable::create(*table, ports);
      if (!local) return;
      const In<double> in = *local->input<double>("in");
      std::uint64_t n = 0;
      double last = 0;
      while (!stop.load(std::memory_order_relaxed)) {
        local->pull_in_vars();
        ++n;
        const double first = in[0];
        bool whole = first >= last;
        for (double x : in.values()) whole = whole && x == first;
        if (!whole) torn.fetch_add(1, std::memory_order_relaxed);
        last = first;
      }
      pulls.fetch_add(n, std::memory_order_relaxed);
    });
  }
  std::this_thread::sleep_for(kRunFor);
  stop = true;
  writer.join();
  for (auto& t : readers) t.join();
  EXPECT_EQ(torn.load(), 0U);
  EXPECT_GT(pulls.load(), 0U);
  EXPECT_GT(writes.load(), 0U);
}

// A reader stopped between its steps (here by yielding to a writer that never stops) must either
// see a whole value or know that it did not.
TEST(LappingStress, InterruptedReaderNeverAcceptsAMix) {
  constexpr std::uint32_t kCount = 36;
  const std::vector<VarSpec> vars{{"fast", {ElemType::kF64, kCount}}};
  auto table = GlobalTable::create(test::unique_subsystem("lapstress"), vars);
  ASSERT_TRUE(table) << table.error().message;
  test::RawMapping raw(table->shm_name().substr(std::string("/chimera_").size()));
  const svt_detail::BlockRef block = svt_detail::block_ref(raw.base(), 0);

  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> writes{0};
  std::thread writer(writer_loop, std::ref(*table), 0, kCount, std::cref(stop), std::ref(writes));
  std::uint64_t accepted = 0;
  std::uint64_t refused = 0;
  std::uint64_t mixes = 0;
  std::vector<std::uint64_t> words(kCount);
  const auto deadline = std::chrono::steady_clock::now() + kRunFor;
  while (std::chrono::steady_clock::now() < deadline) {
    const std::uint64_t v = svt_detail::read_version(block);
    if (v == 0) continue;
    const std::uint64_t s1 = svt_detail::read_open(block, v);
    std::this_thread::yield();
    if (s1 != 2 * v) {
      ++refused;
      continue;
    }
    svt_detail::read_copy(block, v, words.data());
    std::this_thread::yield();
    if (!svt_detail::read_close(block, v, s1)) {
      ++refused;
      continue;
    }
    ++accepted;
    for (std::uint64_t w : words) {
      double x = 0;
      std::memcpy(&x, &w, sizeof x);
      if (x != static_cast<double>(v)) {
        ++mixes;
        break;
      }
    }
  }
  stop = true;
  writer.join();
  EXPECT_EQ(mixes, 0U);
  EXPECT_GT(accepted + refused, 0U);
  std::cout << accepted << " whole reads accepted, " << refused << " lapped reads refused, " << writes.load()
            << " writes\n";
}

}  // namespace
}  // namespace chimera
