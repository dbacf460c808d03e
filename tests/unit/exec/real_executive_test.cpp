// The real clock: threads, absolute releases, signals through the mailbox, the data-flow rule
// with real threads. Behaviour only; timing figures live in the benchmarks.

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/exec/subsystem.hpp"
#include "support/probe_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

std::unique_ptr<Subsystem> make(const std::string& tasks_yaml) {
  testing::calls().clear();
  auto spec = load_subsystem_text("subsystem: realexec\ntasks:\n" + tasks_yaml, "real.yaml", testing::test_registry());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  RunOptions o;
  o.clock = ClockKind::kReal;
  o.shm_suffix = testing::unique_suffix();
  o.realtime_priorities = false;  // ordinary threads: the behaviour must not depend on SCHED_FIFO
  auto s = Subsystem::create(*spec, testing::test_registry(), o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  return std::move(*s);
}

TEST(RealExecutive, RunsSignalsAndStopsCleanly) {
  // Soft tasks: a deadline missed on a loaded machine must not send them to ERROR here.
  auto s = make(
      "  - {name: c, module: counter, period: 2ms, criticality: soft}\n"
      "  - {name: p, module: probe, period: 2ms, criticality: soft}\n");
  ASSERT_TRUE(s->start().ok());
  s->run_for(100 * kMs);
  auto snap = s->snapshot();
  ASSERT_EQ(snap.size(), 2u);
  EXPECT_EQ(snap[0].state, TaskState::kOn);
  EXPECT_GT(snap[0].stats.cycles, 10u) << "the task cycles on its own thread";
  ASSERT_TRUE(s->signal("c", Signal::kOff).ok());
  const auto frozen = s->get("count")->at(0);
  s->run_for(200 * kMs);
  EXPECT_EQ(s->get("count")->at(0), frozen) << "an OFF task does not cycle";
  ASSERT_TRUE(s->signal("c", Signal::kOn).ok());
  s->run_for(200 * kMs);
  EXPECT_GT(s->get("count")->at(0), frozen);
  s->stop();
  EXPECT_EQ(testing::calls()["p"][testing::kOff], 1);
  EXPECT_EQ(testing::calls()["p"][testing::kKill], 1);
}

TEST(RealExecutive, AFailingTaskGoesToErrorAndTheOtherRunsOn) {
  auto s = make(
      "  - {name: c, module: counter, period: 2ms, criticality: soft}\n"
      "  - {name: p, module: probe, period: 2ms, params: {fail: cycle, fail_after: 3}}\n");
  ASSERT_TRUE(s->start().ok());
  s->run_for(200 * kMs);
  const auto before = s->get("count")->at(0);
  s->run_for(200 * kMs);
  auto snap = s->snapshot();
  EXPECT_EQ(snap[1].state, TaskState::kError);
  EXPECT_EQ(snap[1].stats.cycles, 4u);
  EXPECT_GT(s->get("count")->at(0), before);
  EXPECT_TRUE(s->hard_task_failed());
}

TEST(RealExecutive, SameRateConsumerLagsOnlyWhenItsProducerIsLatePastTheBound) {
  // The consumer is listed first and both threads are released at the same instants; the
  // precedence rule must order them. Without it, most cycles would lag. A shared machine may hold
  // the producer's thread past the bound (half the consumer's deadline), and the executive then
  // records that it gave up: every lagged cycle must be one of those, whatever the machine's load.
  auto s = make(
      "  - {name: f, module: follower, period: 5ms, criticality: soft, late: run}\n"
      "  - {name: c, module: counter, period: 5ms, criticality: soft, late: run}\n");
  ASSERT_TRUE(s->start().ok());
  s->run_for(500 * kMs);
  auto off_r = s->signal("f", Signal::kOff);
  ASSERT_TRUE(off_r.ok()) << off_r.error().message;
  const double cycles = s->get("follower_cycles")->at(0);
  const double lagged = s->get("lagged")->at(0);
  std::uint64_t gave_up = 0;
  for (const auto& t : s->snapshot())
    if (t.name == "f") gave_up = t.stats.order_timeouts;
  EXPECT_GT(cycles, 20);
  EXPECT_LE(lagged, static_cast<double>(gave_up)) << lagged << " of " << cycles << " cycles lagged";
}

}  // namespace
}  // namespace chimera
