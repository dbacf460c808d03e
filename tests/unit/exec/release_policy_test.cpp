// The release policy both executives follow (src/exec/release_policy.hpp), each rule on its own:
// the grid, late releases, the same-rate rule's wait, and a switch's boundary.

#include "exec/release_policy.hpp"

#include <gtest/gtest.h>

namespace chimera::release_policy {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(ReleasePolicyGrid, ATaskTurningOnJoinsAtTheNextWholeMultipleOfItsPeriod) {
  EXPECT_EQ(first_release_index(0, kMs), 0);
  EXPECT_EQ(first_release_index(1, kMs), 1);
  EXPECT_EQ(first_release_index(kMs, kMs), 1) << "a grid point itself is at or after";
  EXPECT_EQ(first_release_index(kMs + 1, kMs), 2);
  EXPECT_EQ(first_release_index(29 * kMs, 10 * kMs), 3);
}

TEST(ReleasePolicyGrid, ASwitchCommitsAtTheFirstBoundaryStrictlyAfter) {
  EXPECT_EQ(next_boundary_after(0, kMs), kMs);
  EXPECT_EQ(next_boundary_after(kMs, kMs), 2 * kMs) << "strictly after: a boundary now is too late to post";
  EXPECT_EQ(next_boundary_after(kMs - 1, kMs), kMs);
  // The real clock asks with its margin added: 0.85 ms + 0.2 ms -> the boundary at 2 ms.
  EXPECT_EQ(next_boundary_after(850'000 + 200'000, kMs), 2 * kMs);
}

TEST(ReleasePolicyLate, UnderRunNothingIsSkipped) {
  const LateReleases late = late_releases(LatePolicy::kRun, 10 * kMs, 50 * kMs, kMs, kMs);
  EXPECT_EQ(late.skipped, 0U);
  EXPECT_EQ(late.next_release, 10 * kMs) << "every late release runs, one after another";
}

TEST(ReleasePolicyLate, UnderSkipOnlyReleasesWhoseDeadlineHasPassedAreSkipped) {
  // Release at 10 ms, period and deadline 1 ms, now 13.5 ms: the releases at 10, 11 and 12 ms had
  // their deadlines (11, 12, 13 ms) pass; the one at 13 ms (deadline 14 ms) is still worth running.
  LateReleases late = late_releases(LatePolicy::kSkip, 10 * kMs, 13 * kMs + 500'000, kMs, kMs);
  EXPECT_EQ(late.skipped, 3U);
  EXPECT_EQ(late.next_release, 13 * kMs);
  // Exactly at a deadline nothing has passed yet.
  late = late_releases(LatePolicy::kSkip, 10 * kMs, 11 * kMs, kMs, kMs);
  EXPECT_EQ(late.skipped, 0U);
  late = late_releases(LatePolicy::kSkip, 10 * kMs, 11 * kMs + 1, kMs, kMs);
  EXPECT_EQ(late.skipped, 1U);
  EXPECT_EQ(late.next_release, 11 * kMs);
  // On time: nothing.
  late = late_releases(LatePolicy::kSkip, 10 * kMs, 10 * kMs, kMs, kMs);
  EXPECT_EQ(late.skipped, 0U);
}

TEST(ReleasePolicyLate, AShortDeadlineSkipsSooner) {
  // Deadline 0.2 ms of a 1 ms period: at 10.5 ms the release at 10 ms is already past saving.
  const LateReleases late = late_releases(LatePolicy::kSkip, 10 * kMs, 10 * kMs + 500'000, kMs, 200'000);
  EXPECT_EQ(late.skipped, 1U);
  EXPECT_EQ(late.next_release, 11 * kMs) << "ahead of now: the task waits for it";
}

TEST(ReleasePolicyLate, NoDeadlineNeverSkips) {
  EXPECT_EQ(late_releases(LatePolicy::kSkip, 0, 1'000 * kMs, kMs, 0).skipped, 0U);
}

TEST(ReleasePolicyLate, ALongStallIsCountedAtOnce) {
  // A 1 ns period stalled for a second: a billion releases, counted in one step.
  const LateReleases late = late_releases(LatePolicy::kSkip, 0, 1'000'000'000, 1, 1);
  EXPECT_EQ(late.skipped, 999'999'999U);
  EXPECT_EQ(late.next_release, 999'999'999);
}

TEST(ReleasePolicySameRate, AConsumerWaitsOnlyForAProducerThatWillRunItsReleaseNext) {
  const std::int64_t release = 7;
  EXPECT_TRUE(waits_for_producer(true, false, false, 7, release)) << "about to run this release";
  EXPECT_TRUE(waits_for_producer(true, false, true, 7, release)) << "about to run it, the one before done";
  EXPECT_TRUE(waits_for_producer(true, false, true, 6, release)) << "done with 6, its next not published yet";
  EXPECT_FALSE(waits_for_producer(true, false, false, 6, release)) << "behind: 6 still to run, then 7";
  EXPECT_FALSE(waits_for_producer(true, false, false, 2, release)) << "behind: catching up after a stall";
  EXPECT_FALSE(waits_for_producer(true, true, true, 7, release)) << "done already";
  EXPECT_FALSE(waits_for_producer(false, false, true, 7, release)) << "not ON";
  EXPECT_FALSE(waits_for_producer(true, false, true, 8, release)) << "turned on after it, or skipped it";
  EXPECT_FALSE(waits_for_producer(true, false, true, -1, release)) << "not released at all";
}

TEST(ReleasePolicySameRate, TheWaitIsBoundedByHalfTheDeadlineFromWhenItStarts) {
  EXPECT_EQ(producer_wait_until(10 * kMs, 10 * kMs, kMs), 10 * kMs + 500'000);
  EXPECT_EQ(producer_wait_until(10 * kMs, 9 * kMs, kMs), 10 * kMs + 500'000) << "early: from the release";
  // Catching up after a stall, every release is in the past: the bound counts from now, so the
  // order still holds instead of every wait giving up at once.
  EXPECT_EQ(producer_wait_until(10 * kMs, 40 * kMs, kMs), 40 * kMs + 500'000);
}

TEST(ReleasePolicyWakeLead, OnlyAThreadWaitingOnAnotherCpuWakesEarlyAndNeverByMoreThanATwentiethOfItsPeriod) {
  EXPECT_EQ(wake_lead(false, kMs), 0) << "nothing to wait for on another CPU: it would spin for nothing";
  EXPECT_EQ(wake_lead(true, kMs), 50'000) << "1 kHz: the whole lead, 5 % of the period";
  EXPECT_EQ(wake_lead(true, 10 * kMs), kMaxWakeLeadNs) << "a slower task spins no longer";
  EXPECT_EQ(wake_lead(true, 200'000), 10'000) << "5 kHz: a twentieth of the period";
  EXPECT_EQ(wake_lead(true, 0), 0) << "aperiodic";
}

}  // namespace
}  // namespace chimera::release_policy
