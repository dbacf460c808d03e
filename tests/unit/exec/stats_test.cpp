#include "chimera/exec/stats.hpp"

#include <gtest/gtest.h>

namespace chimera {
namespace {

TEST(LatencyHistogram, BucketsAreMonotonicAndTight) {
  int previous = -1;
  for (std::int64_t v : {0L, 1L, 31L, 32L, 33L, 63L, 64L, 1000L, 1'000'000L, 1'000'000'000L}) {
    const int b = LatencyHistogram::bucket_of(v);
    EXPECT_GT(b, previous) << v;
    previous = b;
    EXPECT_GE(LatencyHistogram::upper_bound_of(b), v);
    EXPECT_LE(LatencyHistogram::upper_bound_of(b), v + v / 16 + 1) << "about 3% resolution at " << v;
  }
}

TEST(LatencyHistogram, PercentilesOfAKnownDistribution) {
  LatencyHistogram h;
  for (int i = 1; i <= 1000; ++i) h.record(i * 1000);  // 1 us .. 1 ms
  EXPECT_EQ(h.count(), 1000u);
  EXPECT_EQ(h.max(), 1'000'000);
  EXPECT_NEAR(static_cast<double>(h.percentile(0.5)), 500'000.0, 500'000.0 * 0.04);
  EXPECT_NEAR(static_cast<double>(h.percentile(0.99)), 990'000.0, 990'000.0 * 0.04);
  EXPECT_EQ(h.percentile(1.0), 1'000'000);
  h.reset();
  EXPECT_EQ(h.percentile(0.5), 0);
}

TEST(TaskStats, OnTheVirtualClockExecutionTimesAreSimulatedAndTheHostsKeptApart) {
  TaskStats s;
  EXPECT_FALSE(s.snapshot().exec_simulated);
  s.record_cycle(0, 2'000'000, 2'000'000, false, false);  // 2 ms simulated...
  s.record_host_exec(1500);                               // ... that took the host 1.5 µs
  s.record_cycle(0, 4'000'000, 4'000'000, false, false);
  s.record_host_exec(2500);
  auto snap = s.snapshot();
  EXPECT_TRUE(snap.exec_simulated);
  EXPECT_EQ(snap.exec_mean_ns, 3'000'000);
  EXPECT_EQ(snap.exec_max_ns, 4'000'000);
  EXPECT_EQ(snap.host_exec_mean_ns, 2000);
  EXPECT_EQ(snap.host_exec_max_ns, 2500);
  s.reset();
  EXPECT_FALSE(s.snapshot().exec_simulated);
  EXPECT_EQ(s.snapshot().host_exec_max_ns, 0);
  // On the real clock the host's figures are the execution times themselves.
  s.record_cycle(0, 700, 900, false, false);
  snap = s.snapshot();
  EXPECT_FALSE(snap.exec_simulated);
  EXPECT_EQ(snap.host_exec_mean_ns, 700);
  EXPECT_EQ(snap.host_exec_max_ns, 700);
}

TEST(TaskStats, CountsCyclesMissesAndExecutionTimes) {
  TaskStats s;
  s.record_cycle(100, 1000, 1100, false, false);
  s.record_cycle(300, 3000, 3300, true, true);
  s.record_skipped(2);
  const auto snap = s.snapshot();
  EXPECT_EQ(snap.cycles, 2u);
  EXPECT_EQ(snap.missed, 3u);  // one late cycle, two skipped releases
  EXPECT_EQ(snap.skipped, 2u);
  EXPECT_EQ(snap.overruns, 1u);
  EXPECT_EQ(snap.exec_mean_ns, 2000);
  EXPECT_EQ(snap.exec_max_ns, 3000);
  EXPECT_EQ(snap.latency_max_ns, 300);
  EXPECT_EQ(snap.response_max_ns, 3300);
  // The profile: one bucket per distinct value here, each holding one record.
  ASSERT_EQ(snap.exec_histogram.size(), 2u);
  EXPECT_NEAR(static_cast<double>(snap.exec_histogram[0].first), 1000.0, 1000.0 * 0.04);
  EXPECT_EQ(snap.exec_histogram[0].second, 1u);
  EXPECT_NEAR(static_cast<double>(snap.exec_histogram[1].first), 3000.0, 3000.0 * 0.04);
  ASSERT_EQ(snap.latency_histogram.size(), 2u);
}

}  // namespace
}  // namespace chimera
