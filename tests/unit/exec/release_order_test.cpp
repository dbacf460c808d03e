// The same-rate data-flow rule (ros2_control issue 2420 is the failure it prevents): a consumer
// released at the same instant as its producer reads the value of that instant, whatever the
// order of the tasks in the file.

#include "chimera/analysis/release_order.hpp"

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/probe_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

std::unique_ptr<Subsystem> run_file(const std::string& tasks_yaml, std::int64_t for_ns) {
  auto spec = load_subsystem_text("subsystem: order\ntasks:\n" + tasks_yaml, "order.yaml", testing::test_registry());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  RunOptions o;
  o.clock = ClockKind::kVirtual;
  o.shm_suffix = testing::unique_suffix();
  auto s = Subsystem::create(*spec, testing::test_registry(), o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  EXPECT_TRUE((*s)->start().ok());
  (*s)->run_for(for_ns);
  return std::move(*s);
}

TEST(ReleaseOrder, ConsumerListedFirstStillReadsTheSameInstantsValue) {
  auto s = run_file(
      "  - {name: f, module: follower, period: 1ms}\n"
      "  - {name: c, module: counter, period: 1ms}\n",
      100 * kMs);
  EXPECT_EQ(s->get("count")->at(0), 100.0);
  EXPECT_EQ(s->get("copy")->at(0), 100.0) << "no cycle of lag";
  EXPECT_EQ(s->get("lagged")->at(0), 0.0);
}

TEST(ReleaseOrder, ChainOfThreeInReverseFileOrder) {
  auto s = run_file(
      "  - {name: f2, module: follower, period: 1ms, rename: {count: copy, copy: copy2, lagged: lagged2, "
      "follower_cycles: fc2}}\n"
      "  - {name: f1, module: follower, period: 1ms}\n"
      "  - {name: c, module: counter, period: 1ms}\n",
      50 * kMs);
  EXPECT_EQ(s->get("copy2")->at(0), 50.0);
  EXPECT_EQ(s->get("lagged2")->at(0), 0.0);
}

TEST(ReleaseOrder, RanksAndPredecessorsFollowDataFlowAndCutLoopsAtTheFirstListed) {
  auto spec = load_subsystem_text(
      "subsystem: order\ntasks:\n"
      "  - {name: f, module: follower, period: 1ms}\n"
      "  - {name: c, module: counter, period: 1ms}\n"
      "  - {name: slow, module: follower, period: 2ms, rename: {copy: c2, lagged: l2, follower_cycles: fc3}}\n",
      "order.yaml", testing::test_registry());
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  const auto resolution = resolve_subsystem(*spec, testing::test_registry());
  const analysis::ReleaseOrder order = analysis::compute_release_order(resolution.subsystem);
  EXPECT_EQ(order.rank[1], 0);  // c, the producer, first
  EXPECT_EQ(order.rank[0], 1);  // f after it
  ASSERT_EQ(order.predecessors[0].size(), 1u);
  EXPECT_EQ(order.predecessors[0][0], 1);
  EXPECT_TRUE(order.predecessors[2].empty()) << "another period is not a predecessor";
}

TEST(ReleaseOrder, ChainsJoinTasksOfOnePeriodThatFeedEachOtherEitherWay) {
  // c -> f (count) at 1 ms is one chain, named by its first task in the file (f, index 0); a
  // follower at 2 ms reads `count` too but is of another period: a chain of its own; so is a
  // counter at 1 ms whose output nobody of its period reads.
  auto spec = load_subsystem_text(
      "subsystem: order\ntasks:\n"
      "  - {name: f, module: follower, period: 1ms}\n"
      "  - {name: c, module: counter, period: 1ms}\n"
      "  - {name: slow, module: follower, period: 2ms, rename: {copy: c2, lagged: l2, follower_cycles: fc3}}\n"
      "  - {name: lone, module: counter, period: 1ms, rename: {count: other}}\n",
      "order.yaml", testing::test_registry());
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  const auto resolution = resolve_subsystem(*spec, testing::test_registry());
  const analysis::ReleaseOrder order = analysis::compute_release_order(resolution.subsystem);
  EXPECT_EQ(order.chain, (std::vector<int>{0, 0, 2, 3}));
}

}  // namespace
}  // namespace chimera
