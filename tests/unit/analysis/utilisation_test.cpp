// Utilisation, its exact comparison with 1, the Liu and Layland bound, and the analysed C.

#include "chimera/analysis/utilisation.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace chimera::analysis {
namespace {

TEST(LiuLayland, BoundForOneTwoThreeAndMany) {
  EXPECT_DOUBLE_EQ(liu_layland_bound(1), 1.0);
  EXPECT_NEAR(liu_layland_bound(2), 0.828427, 1e-6);  // 2 (sqrt 2 - 1)
  EXPECT_NEAR(liu_layland_bound(3), 0.779763, 1e-6);
  EXPECT_NEAR(liu_layland_bound(1000), std::log(2.0), 1e-3);
  EXPECT_DOUBLE_EQ(liu_layland_bound(0), 1.0);
}

TEST(Utilisation, SumOfCOverT) {
  const std::vector<Demand> tasks{{1, 4, 4}, {2, 6, 6}, {3, 8, 8}};  // 23/24
  EXPECT_NEAR(utilisation(tasks), 23.0 / 24.0, 1e-12);
  EXPECT_TRUE(utilisation_at_most_one(tasks));
}

TEST(Utilisation, ExactlyOneIsAtMostOne) {
  // 1/3 + 1/3 + 1/3 is exactly 1; in doubles it may round either way.
  EXPECT_TRUE(utilisation_at_most_one(std::vector<Demand>{{1, 3, 3}, {1, 3, 3}, {1, 3, 3}}));
  EXPECT_TRUE(utilisation_at_most_one(std::vector<Demand>{{2, 4, 4}, {3, 6, 6}}));
}

TEST(Utilisation, OneLcmPartAboveOneIsTooMuch) {
  // 1/2 + 1/3 + 1/6 = 1; one ns more on the last task is 1 + 1/6e9, which a double cannot see.
  const std::int64_t s = 1'000'000'000;
  EXPECT_TRUE(utilisation_at_most_one(std::vector<Demand>{{s, 2 * s, 2 * s}, {s, 3 * s, 3 * s}, {s, 6 * s, 6 * s}}));
  EXPECT_FALSE(
      utilisation_at_most_one(std::vector<Demand>{{s, 2 * s, 2 * s}, {s, 3 * s, 3 * s}, {s + 1, 6 * s, 6 * s}}));
}

TEST(Utilisation, OneTaskLongerThanItsPeriod) { EXPECT_FALSE(utilisation_at_most_one(std::vector<Demand>{{5, 4, 4}})); }

TEST(Utilisation, CoprimePeriodsBeyondTheExactRangeStillCompare) {
  // Primes near 1e9: their product overflows 127 bits after four of them.
  std::vector<Demand> tasks;
  for (const std::int64_t p : {999'999'937LL, 999'999'929LL, 999'999'893LL, 999'999'883LL, 999'999'797LL})
    tasks.push_back(Demand{p / 10, p, p});
  EXPECT_TRUE(utilisation_at_most_one(tasks));  // 0.5
  tasks.push_back(Demand{999'999'761LL / 2 + 1000, 999'999'761LL, 999'999'761LL});
  EXPECT_FALSE(utilisation_at_most_one(tasks));  // 1 + 1e-6, in long double
}

TEST(DemandOf, AddsTheOverheadToC) {
  TaskModel t{.name = "a", .wcet_ns = 200'000, .period_ns = 1'000'000};
  const auto d = demand_of(t, AnalysisOptions{.overhead_ns = 1'000});
  ASSERT_TRUE(d);
  EXPECT_EQ(d->c_ns, 201'000);
  EXPECT_EQ(d->t_ns, 1'000'000);
  EXPECT_EQ(d->d_ns, 1'000'000);  // no deadline of its own: the period
}

TEST(DemandOf, AServerCountsItsBudgetPlusOneJob) {
  TaskModel s{.name = "cmd", .wcet_ns = 2'000'000, .job_wcet_ns = 500'000, .period_ns = 10'000'000, .server = true};
  const auto d = demand_of(s, AnalysisOptions{.overhead_ns = 1'000});
  ASSERT_TRUE(d);
  EXPECT_EQ(d->c_ns, 2'501'000);
  s.job_wcet_ns = 0;  // the overrun cannot be bounded
  EXPECT_FALSE(demand_of(s, AnalysisOptions{}));
}

TEST(DemandOf, NoneForUnknownCOrBackground) {
  EXPECT_FALSE(demand_of(TaskModel{.name = "a", .period_ns = 1000}, AnalysisOptions{}));
  EXPECT_FALSE(demand_of(TaskModel{.name = "b", .wcet_ns = 10}, AnalysisOptions{}));  // aperiodic
  EXPECT_TRUE(is_background(TaskModel{.name = "b", .wcet_ns = 10}));
}

}  // namespace
}  // namespace chimera::analysis
