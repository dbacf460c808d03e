// The sporadic server (src/exec/sporadic_server.hpp): budget charged at a job's end, given back
// one server period after the job started, a full ring merged later, never early.

#include "exec/sporadic_server.hpp"

#include <gtest/gtest.h>

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(SporadicServer, StartsFullAndChargesWhatAJobUsed) {
  SporadicServer s;
  EXPECT_TRUE(s.exhausted()) << "nothing before it turns on";
  s.turn_on(2 * kMs);
  EXPECT_EQ(s.budget(), 2 * kMs);
  s.charge(0, 500'000, 10 * kMs);
  EXPECT_EQ(s.budget(), 1'500'000);
  EXPECT_FALSE(s.exhausted());
  EXPECT_EQ(s.next_refill(), 10 * kMs) << "one server period after the job started";
}

TEST(SporadicServer, GivesBackEachRefillWhenItIsDueAndNotBefore) {
  SporadicServer s;
  s.turn_on(kMs);
  s.charge(0, 600'000, 10 * kMs);
  s.charge(2 * kMs, 400'000, 10 * kMs);
  EXPECT_TRUE(s.exhausted());
  s.refill(10 * kMs - 1);
  EXPECT_TRUE(s.exhausted()) << "not due yet";
  s.refill(10 * kMs);
  EXPECT_EQ(s.budget(), 600'000);
  EXPECT_EQ(s.next_refill(), 12 * kMs);
  s.refill(50 * kMs);
  EXPECT_EQ(s.budget(), kMs);
  EXPECT_EQ(s.pending(), 0U);
  EXPECT_EQ(s.next_refill(), SporadicServer::kNever);
}

TEST(SporadicServer, AJobMayOverrunTheBudgetByItselfOnly) {
  SporadicServer s;
  s.turn_on(kMs);
  s.charge(0, 3 * kMs, 10 * kMs);  // a job may start with any budget left and run long
  EXPECT_EQ(s.budget(), -2 * kMs);
  s.refill(10 * kMs);
  EXPECT_EQ(s.budget(), kMs) << "what it used comes back whole";
}

TEST(SporadicServer, TurningOnAgainDoesNotRefillWhatIsStillOwed) {
  SporadicServer s;
  s.turn_on(kMs);
  s.charge(0, kMs, 10 * kMs);
  s.turn_on(kMs);  // off and on again before the refill
  EXPECT_TRUE(s.exhausted()) << "the budget comes back with its refill, not with on";
}

TEST(SporadicServer, AFullRingMergesIntoTheLastRefillLaterNeverEarlier) {
  SporadicServer s;
  s.turn_on(1'000 * kMs);
  for (std::size_t j = 0; j < SporadicServer::kMaxRefills; ++j)
    s.charge(static_cast<std::int64_t>(j) * kMs, 1'000, 100 * kMs);
  EXPECT_EQ(s.pending(), SporadicServer::kMaxRefills);
  s.charge(500 * kMs, 7'000, 100 * kMs);  // no room: merged into the last, at the later time
  EXPECT_EQ(s.pending(), SporadicServer::kMaxRefills);
  const std::int64_t before = s.budget();
  s.refill(100 * kMs + 63 * kMs);  // due time of the last un-merged one
  EXPECT_EQ(s.budget(), before + 63 * 1'000) << "the last refill waits for the merged time";
  s.refill(600 * kMs);
  EXPECT_EQ(s.budget(), before + 63 * 1'000 + 1'000 + 7'000);
}

}  // namespace
}  // namespace chimera
