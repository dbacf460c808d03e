// A writer stopped half way through a write (as if preempted) must not hold up any reader: they
// get the last whole value at once, told truthfully whether it is new to them, and the new value
// as soon as the writer finishes.

#include <algorithm>
#include <atomic>
#include <future>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/svt/global_table.hpp"
#include "svt/global_table_test_access.hpp"
#include "unit/svt/svt_test_support.hpp"

namespace chimera {
namespace {

constexpr std::uint32_t kCount = 36;
constexpr int kReadsEach = 10000;

bool all_equal(const std::vector<double>& v, double expected) {
  for (double x : v) {
    if (x != expected) return false;
  }
  return true;
}

/// Runs `reads` reads of `v` on a thread of its own, each starting from `seen` with a copy that
/// holds `held`, and counts those that did not return exactly `want`/`want_version`/`want_value`.
std::uint64_t reads_elsewhere(const GlobalTable& table, VarIndex v, std::uint64_t seen, double held, Freshness want,
                              std::uint64_t want_version, double want_value) {
  return std::async(std::launch::async,
                    [&] {
                      std::uint64_t wrong = 0;
                      std::vector<double> copy(kCount, held);
                      for (int i = 0; i < kReadsEach; ++i) {
                        std::fill(copy.begin(), copy.end(), held);
                        const ReadOutcome r = table.read(v, copy.data(), seen);
                        if (r.freshness != want || r.version != want_version || !all_equal(copy, want_value)) ++wrong;
                      }
                      return wrong;
                    })
      .get();
}

// Param: whole writes before the interrupted one; 5 makes the interrupted write reuse a slot.
class PreemptedWriter : public ::testing::TestWithParam<int> {};

TEST_P(PreemptedWriter, ReadersGetTheLastWholeValueWithoutWaiting) {
  const int before = GetParam();
  const std::vector<VarSpec> vars{{"x", {ElemType::kF64, kCount}}};
  auto table = GlobalTable::create(test::unique_subsystem("preempt"), vars);
  ASSERT_TRUE(table) << table.error().message;
  auto attached = GlobalTable::attach(table->shm_name().substr(std::string("/chimera_").size()));
  ASSERT_TRUE(attached) << attached.error().message;
  const auto a_version = static_cast<std::uint64_t>(before);
  const double a = 1.0;
  const double b = 2.0;
  {
    std::vector<double> value(kCount);
    for (int k = 1; k <= before; ++k) {
      std::fill(value.begin(), value.end(), k == before ? a : -k);
      table->write(0, value.data());
    }
  }

  // The writer thread stores half of B, then stops until told to go on.
  std::promise<void> paused;
  std::promise<void> resume;
  std::thread writer([&] {
    const std::vector<double> value(kCount, b);
    GlobalTableTestAccess::begin_write(*table, 0);
    GlobalTableTestAccess::store_bytes(*table, 0, 0, value.data(), kCount / 2 * sizeof(double));
    paused.set_value();
    resume.get_future().wait();
    GlobalTableTestAccess::store_bytes(*table, 0, kCount / 2 * sizeof(double), value.data() + kCount / 2,
                                       kCount / 2 * sizeof(double));
    GlobalTableTestAccess::end_write(*table, 0);
  });
  paused.get_future().wait();

  EXPECT_EQ(table->version(0), a_version);
  // A reader that already holds A: nothing newer, copy untouched.
  EXPECT_EQ(reads_elsewhere(*attached, 0, a_version, a, Freshness::kOld, a_version, a), 0U);
  // A fresh reader: A, as new. Had it needed retries it would have been starved into kNoData.
  EXPECT_EQ(reads_elsewhere(*attached, 0, 0, 0.0, Freshness::kNew, a_version, a), 0U);
  // A reader holding something older than A: A, as new.
  if (before > 1) {
    EXPECT_EQ(reads_elsewhere(*table, 0, a_version - 1, -(a_version - 1.0), Freshness::kNew, a_version, a), 0U);
  }

  resume.set_value();
  writer.join();
  EXPECT_EQ(table->version(0), a_version + 1);
  EXPECT_EQ(reads_elsewhere(*attached, 0, a_version, a, Freshness::kNew, a_version + 1, b), 0U);
  EXPECT_EQ(reads_elsewhere(*attached, 0, a_version + 1, b, Freshness::kOld, a_version + 1, b), 0U);
}

INSTANTIATE_TEST_SUITE_P(WritesBefore, PreemptedWriter, ::testing::Values(1, 4, 5));

TEST(PreemptedWriter, ReadersOfOtherVariablesAreUnaffected) {
  const std::vector<VarSpec> vars{{"stuck", {ElemType::kF64, kCount}}, {"moving", {ElemType::kF64, kCount}}};
  auto table = GlobalTable::create(test::unique_subsystem("preempt_other"), vars);
  ASSERT_TRUE(table) << table.error().message;
  GlobalTableTestAccess::begin_write(*table, 0);  // never finished in this test
  const std::vector<double> value(kCount, 3.0);
  table->write(1, value.data());
  EXPECT_EQ(reads_elsewhere(*table, 1, 0, 0.0, Freshness::kNew, 1, 3.0), 0U);
  EXPECT_EQ(reads_elsewhere(*table, 0, 0, 0.0, Freshness::kNoData, 0, 0.0), 0U);
}

}  // namespace
}  // namespace chimera
