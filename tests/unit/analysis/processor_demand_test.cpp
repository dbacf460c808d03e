// The EDF tests: utilisation for D >= T, processor demand (QPA) for constrained deadlines, on
// textbook sets and against a brute-force EDF simulation of generated sets.

#include "chimera/analysis/processor_demand.hpp"

#include <vector>

#include <gtest/gtest.h>

#include "chimera/analysis/utilisation.hpp"
#include "unit/analysis/simulate.hpp"

namespace chimera::analysis {
namespace {

TEST(EdfTest, ImplicitDeadlinesUpToFullUtilisation) {
  // The set rate-monotonic priorities cannot schedule (2, 5), (4, 7): U = 0.971 <= 1.
  const auto r = edf_test(std::vector<Demand>{{2, 5, 5}, {4, 7, 7}});
  EXPECT_EQ(r.outcome, EdfOutcome::kFeasible);
  EXPECT_TRUE(r.utilisation_decides);
  // Lipari's (1, 4), (2, 6), (3, 8), U = 23/24; and exactly 1.
  EXPECT_EQ(edf_test(std::vector<Demand>{{1, 4, 4}, {2, 6, 6}, {3, 8, 8}}).outcome, EdfOutcome::kFeasible);
  EXPECT_EQ(edf_test(std::vector<Demand>{{2, 4, 4}, {3, 6, 6}}).outcome, EdfOutcome::kFeasible);
}

TEST(EdfTest, OverloadedAboveOne) {
  const auto r = edf_test(std::vector<Demand>{{3, 5, 5}, {3, 6, 6}});
  EXPECT_EQ(r.outcome, EdfOutcome::kOverloaded);
  EXPECT_NEAR(r.utilisation, 1.1, 1e-9);
}

TEST(EdfTest, DeadlinesLongerThanPeriodsNeedOnlyUtilisation) {
  const auto r = edf_test(std::vector<Demand>{{2, 5, 9}, {4, 7, 7}});
  EXPECT_EQ(r.outcome, EdfOutcome::kFeasible);
  EXPECT_TRUE(r.utilisation_decides);
}

// (C, D, T) = (2, 4, 6), (2, 5, 8), (3, 7, 9): U = 0.917, the bound of George et al. is
// sum (T - D) U / (1 - U) = 25, and h(t) <= t at every deadline up to it, with h(16) = 16 exact:
// t    4  5  7  10  13  16  21  22  25
// h(t) 2  4  7   9  11  16  18  20  23
const std::vector<Demand> kConstrained{{2, 6, 4}, {2, 8, 5}, {3, 9, 7}};

TEST(ProcessorDemand, TheDemandBoundFunction) {
  const std::vector<std::pair<std::int64_t, std::int64_t>> table{{3, 0},   {4, 2},   {5, 4},   {7, 7},   {10, 9},
                                                                 {13, 11}, {16, 16}, {21, 18}, {22, 20}, {25, 23}};
  for (const auto& [t, h] : table) EXPECT_EQ(processor_demand(kConstrained, t), h) << "t = " << t;
}

TEST(EdfTest, ConstrainedDeadlinesFeasible) {
  const auto r = edf_test(kConstrained);
  EXPECT_EQ(r.outcome, EdfOutcome::kFeasible);
  EXPECT_FALSE(r.utilisation_decides);
  EXPECT_GT(r.bound_ns, 0);
  // The synchronous busy period 7 -> 9 -> 11 -> 14 -> 16 is shorter than the bound 25 of George
  // et al.; QPA then visits 13, h = 11, h = 9, h = 7 = t, then the deadline before it, 5, where
  // h(5) = 4 <= the shortest deadline: feasible.
  EXPECT_EQ(r.bound_ns, 16);
  EXPECT_EQ(r.points, 5);
}

TEST(EdfTest, ConstrainedDeadlinesInfeasibleBelowFullUtilisation) {
  // The same set with the third deadline at 6: h(6) = 2 + 2 + 3 = 7 > 6, though U = 0.917.
  // QPA: 15 (h 14), 14 (11), 11 (9), 9 (7), 7 (7 = t), then the deadline 6: h(6) = 7.
  const auto r = edf_test(std::vector<Demand>{{2, 6, 4}, {2, 8, 5}, {3, 9, 6}});
  EXPECT_EQ(r.outcome, EdfOutcome::kDemandExceeded);
  EXPECT_EQ(r.points, 6);
  EXPECT_EQ(r.interval_ns, 6);
  EXPECT_EQ(r.demand_ns, 7);
  // Two tasks due at 3 with 2 each, at U = 0.4.
  const auto two = edf_test(std::vector<Demand>{{2, 10, 3}, {2, 10, 3}});
  EXPECT_EQ(two.outcome, EdfOutcome::kDemandExceeded);
  EXPECT_EQ(two.interval_ns, 3);
  EXPECT_EQ(two.demand_ns, 4);
}

TEST(EdfTest, OneJobLongerThanItsDeadline) {
  const auto r = edf_test(std::vector<Demand>{{5, 10, 3}});
  EXPECT_EQ(r.outcome, EdfOutcome::kDemandExceeded);
}

TEST(EdfTest, LargeRealisticNumbersStayExact) {
  // 1 kHz control with a 500 µs deadline beside slower tasks, in ns.
  const std::vector<Demand> tasks{
      {300'000, 1'000'000, 500'000}, {2'000'000, 10'000'000, 4'000'000}, {30'000'000, 100'000'000, 100'000'000}};
  EXPECT_EQ(edf_test(tasks).outcome, EdfOutcome::kFeasible);
  // h(4 ms) = 4 x 0.3 + 2 = 3.2 ms fits; a 2.5 ms deadline for the middle task does not:
  // h(2.5 ms) = 3 x 0.3 + 2 = 2.9 ms > 2.5 ms.
  const std::vector<Demand> tight{
      {300'000, 1'000'000, 500'000}, {2'000'000, 10'000'000, 2'500'000}, {30'000'000, 100'000'000, 100'000'000}};
  const auto r = edf_test(tight);
  EXPECT_EQ(r.outcome, EdfOutcome::kDemandExceeded);
  EXPECT_EQ(r.interval_ns, 2'500'000);
  EXPECT_EQ(r.demand_ns, 2'900'000);
}

TEST(EdfTest, AgreesWithASimulationOfGeneratedSets) {
  // Mostly constrained deadlines, some longer than the period (a mixed set needs QPA too).
  int feasible = 0;
  int infeasible = 0;
  for (const auto& tasks : test::generated_sets(7, 600, 20, 25)) {
    const auto r = edf_test(tasks);
    ASSERT_NE(r.outcome, EdfOutcome::kGaveUp);
    const bool sim = test::simulate(tasks, test::Policy::kEdf, 2 * test::hyperperiod(tasks) + 40).all_met;
    EXPECT_EQ(r.outcome == EdfOutcome::kFeasible, sim) << testing::PrintToString(tasks);
    if (r.outcome == EdfOutcome::kDemandExceeded) {
      EXPECT_GT(processor_demand(tasks, r.interval_ns), r.interval_ns);
    }
    (sim ? feasible : infeasible) += 1;
  }
  // The generator must give both answers often, or the comparison proves little.
  EXPECT_GT(feasible, 50);
  EXPECT_GT(infeasible, 40);
}

// Release jitter J shortens a job's deadline from when it becomes ready: h(t) counts D - J
// (Spuri 1996). Worked by hand.
TEST(EdfTest, JitterShortensTheDeadlineTheDemandCounts) {
  // (2, 10, 10) with J = 5 beside (4, 10, 10): h(5) = 2, h(10) = 6: feasible, by the demand test now.
  const std::vector<Demand> waits{{2, 10, 10, 5}, {4, 10, 10}};
  const EdfTest ok = edf_test(waits);
  EXPECT_EQ(ok.outcome, EdfOutcome::kFeasible);
  EXPECT_FALSE(ok.utilisation_decides);
  EXPECT_EQ(processor_demand(waits, 5), 2);
  // J = 9: ready 1 before its deadline with 2 to do.
  const std::vector<Demand> late{{2, 10, 10, 9}, {4, 10, 10}};
  const EdfTest bad = edf_test(late);
  EXPECT_EQ(bad.outcome, EdfOutcome::kDemandExceeded);
  EXPECT_EQ(bad.interval_ns, 1);
  EXPECT_EQ(bad.demand_ns, 2);
}

TEST(EdfTest, JitterAtTheDeadlineLeavesNoTime) {
  const std::vector<Demand> tasks{{3, 10, 10, 10}};
  EXPECT_EQ(edf_test(tasks).outcome, EdfOutcome::kDemandExceeded);
}

}  // namespace
}  // namespace chimera::analysis
