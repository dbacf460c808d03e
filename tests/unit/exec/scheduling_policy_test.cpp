// The order in which jobs run on the virtual clock is exactly the policy's (issue 3): crafted
// task sets where rate monotonic, deadline monotonic, EDF and MUF choose differently, with the
// execution times given by `virtual_exec`.

#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/run_subsystem.hpp"
#include "support/trace_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

std::unique_ptr<Subsystem> run(const std::string& yaml, std::int64_t for_ns) {
  testing::trace().clear();
  auto s = testing::start_subsystem(yaml, testing::scheduling_registry());
  if (s) s->run_for(for_ns);
  return s;
}

// "a@0 b@2 ...": each job start as task@time in ms.
std::string starts() {
  std::string out;
  for (const auto& e : testing::trace()) {
    if (!out.empty()) out += ' ';
    out += e.task + "@" + std::to_string(e.start_ns / kMs);
  }
  return out;
}

TaskStatsSnapshot stats_of(Subsystem& s, const std::string& task) { return testing::task_of(s, task).stats; }

// Two tasks on one CPU, U = 2/5 + 4/7 = 0.97: feasible under EDF, not under RM (Buttazzo,
// Hard Real-Time Computing Systems, 3rd ed., figure 4.11's kind of set).
std::string two_tasks(const std::string& scheduler) {
  return "subsystem: s\nscheduler: " + scheduler +
         "\ncpus: [0]\ntasks:\n"
         "  - {name: t1, module: tracer, period: 5ms, virtual_exec: 2ms, params: {recover: true}}\n"
         "  - {name: t2, module: tracer, period: 7ms, virtual_exec: 4ms, params: {recover: true}}\n";
}

TEST(SchedulingPolicy, RateMonotonicPreemptsByPeriodAndT2MissesOnce) {
  auto s = run(two_tasks("rm"), 35 * kMs);  // one hyperperiod
  ASSERT_TRUE(s);
  // t1 preempts t2 at 5; t2's first job ends at 8, past its deadline at 7; its second starts late.
  EXPECT_EQ(starts(), "t1@0 t2@2 t1@5 t2@8 t1@10 t2@14 t1@15 t1@20 t2@22 t1@25 t2@28 t1@30");
  EXPECT_EQ(stats_of(*s, "t1").missed, 0u);
  EXPECT_EQ(stats_of(*s, "t2").missed, 1u);
  EXPECT_EQ(stats_of(*s, "t2").response_max_ns, 8 * kMs);
}

TEST(SchedulingPolicy, EdfRunsTheEarliestDeadlineAndMeetsEveryOne) {
  auto s = run(two_tasks("edf"), 35 * kMs);
  ASSERT_TRUE(s);
  // At 5 t2 (deadline 7) keeps the CPU against t1 (deadline 10); at 15 t1 (20) preempts t2 (21);
  // at 30 the deadlines tie (35) and t2, released first, goes on.
  EXPECT_EQ(starts(), "t1@0 t2@2 t1@6 t2@8 t1@12 t2@14 t1@15 t1@20 t2@22 t1@26 t2@28 t1@32");
  EXPECT_EQ(stats_of(*s, "t1").missed, 0u);
  EXPECT_EQ(stats_of(*s, "t2").missed, 0u);
}

TEST(SchedulingPolicy, DeadlineMonotonicRunsTheShorterDeadlineFirst) {
  const std::string tasks =
      "\ncpus: [0]\ntasks:\n"
      "  - {name: a, module: tracer, period: 5ms, virtual_exec: 2ms}\n"
      "  - {name: b, module: tracer, period: 10ms, deadline: 2ms, virtual_exec: 1ms, params: {recover: true}}\n";
  auto rm = run("subsystem: s\nscheduler: rm" + tasks, 10 * kMs);
  ASSERT_TRUE(rm);
  EXPECT_EQ(starts(), "a@0 b@2 a@5");  // b ends at 3, past its 2 ms deadline
  EXPECT_EQ(stats_of(*rm, "b").missed, 1u);
  auto dm = run("subsystem: s\nscheduler: dm" + tasks, 10 * kMs);
  ASSERT_TRUE(dm);
  EXPECT_EQ(starts(), "b@0 a@1 a@5");
  EXPECT_EQ(stats_of(*dm, "b").missed, 0u);
  EXPECT_EQ(stats_of(*dm, "a").missed, 0u);
}

// A hard task of long period beside a soft one of short period, U = 0.5 + 0.6 = 1.1: the soft
// task does not fit in MUF's critical set.
std::string overload(const std::string& scheduler) {
  return "subsystem: s\nscheduler: " + scheduler +
         "\ncpus: [0]\ntasks:\n"
         "  - {name: hard, module: tracer, period: 10ms, virtual_exec: 5ms, params: {recover: true}}\n"
         "  - {name: soft, module: tracer, period: 5ms, virtual_exec: 3ms, criticality: soft}\n";
}

TEST(SchedulingPolicy, MufProtectsTheCriticalSetWhereRateMonotonicDoesNot) {
  auto muf = run(overload("muf"), 100 * kMs);
  ASSERT_TRUE(muf);
  EXPECT_EQ(stats_of(*muf, "hard").missed, 0u) << "a critical task always beats a non-critical one";
  EXPECT_GT(stats_of(*muf, "soft").missed, 0u);
  // soft's late first job runs 5-8; its second, still before its deadline at 10, starts at 8
  // and is preempted by hard's release at 10.
  EXPECT_EQ(starts().substr(0, 28), "hard@0 soft@5 soft@8 hard@10");
  auto rm = run(overload("rm"), 100 * kMs);
  ASSERT_TRUE(rm);
  EXPECT_GT(stats_of(*rm, "hard").missed, 0u) << "under RM the shorter period wins, and the hard task misses";
  EXPECT_EQ(starts().substr(0, 13), "soft@0 hard@3");
}

TEST(SchedulingPolicy, MufOrdersByCriticalityThenDeadlineThenUserPriority) {
  // The critical set takes the shortest periods first (ties: higher user priority first): b and
  // a fit (0.4 + 0.5), c does not (1.05). Between a and b, whose deadlines tie, b's user priority
  // wins; c's higher one cannot lift it above the critical set. Under RM and EDF the ties fall
  // to file order, and c's longer period or later deadline puts it last.
  const std::string tasks =
      "\ncpus: [0]\ntasks:\n"
      "  - {name: a, module: tracer, period: 10ms, virtual_exec: 5ms, criticality: soft}\n"
      "  - {name: b, module: tracer, period: 10ms, virtual_exec: 4ms, criticality: soft, priority: 5}\n"
      "  - {name: c, module: tracer, period: 20ms, virtual_exec: 3ms, criticality: soft, priority: 9}\n";
  ASSERT_TRUE(run("subsystem: s\nscheduler: muf" + tasks, 10 * kMs));
  EXPECT_EQ(starts(), "b@0 a@4 c@9");
  ASSERT_TRUE(run("subsystem: s\nscheduler: edf" + tasks, 10 * kMs));
  EXPECT_EQ(starts(), "a@0 b@5 c@9");
  ASSERT_TRUE(run("subsystem: s\nscheduler: rm" + tasks, 10 * kMs));
  EXPECT_EQ(starts(), "a@0 b@5 c@9");
}

TEST(SchedulingPolicy, TasksOnTwoCpusDoNotDelayEachOther) {
  // The same two tasks as above, each pinned to its own CPU: both start at every release.
  const std::string yaml =
      "subsystem: s\nscheduler: rm\ncpus: [0, 1]\ntasks:\n"
      "  - {name: t1, module: tracer, period: 5ms, virtual_exec: 2ms, cpu: 0}\n"
      "  - {name: t2, module: tracer, period: 7ms, virtual_exec: 4ms, cpu: 1}\n";
  auto s = run(yaml, 15 * kMs);
  ASSERT_TRUE(s);
  EXPECT_EQ(starts(), "t1@0 t2@0 t1@5 t2@7 t1@10 t2@14");
  for (const auto& t : s->snapshot()) EXPECT_EQ(t.stats.latency_max_ns, 0) << t.name;
}

TEST(SchedulingPolicy, SameRateProducersStillRunFirstWithExecutionTimes) {
  // The data-flow rule holds when cycles take time and the consumer is on another CPU: it waits
  // for its producer's job of the same release, then reads that job's value.
  const std::string yaml =
      "subsystem: s\ncpus: [0, 1]\ntasks:\n"
      "  - {name: f, module: follower, period: 5ms, virtual_exec: 1ms, cpu: 0}\n"
      "  - {name: c, module: counter, period: 5ms, virtual_exec: 2ms, cpu: 1}\n";
  auto s = run(yaml, 50 * kMs);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->get("lagged")->at(0), 0.0);
  EXPECT_EQ(s->get("copy")->at(0), s->get("count")->at(0));
  EXPECT_EQ(stats_of(*s, "f").latency_max_ns, 2 * kMs);  // it started when its producer ended
}

}  // namespace
}  // namespace chimera
