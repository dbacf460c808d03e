// Timing failures on the virtual clock: every injected overrun and every deadline miss is
// detected and counted, and handled by criticality: a hard task gets error() (ERROR unless it
// recovers), a soft one carries on under its late-release policy.

#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/run_subsystem.hpp"
#include "support/trace_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

std::unique_ptr<Subsystem> run(const std::string& tasks, std::int64_t for_ns) {
  auto s = testing::start_subsystem("subsystem: timing\ncpus: [0]\ntasks:\n" + tasks, testing::scheduling_registry());
  if (s) s->run_for(for_ns);
  return s;
}

TaskSnapshot task(Subsystem& s, const std::string& name) { return testing::task_of(s, name); }

std::string events_text(Subsystem& s) {
  std::string out;
  for (const auto& e : s.drain_events()) out += e.task + ": " + e.text + "\n";
  return out;
}

TEST(TimingFailures, EveryInjectedOverrunIsDetectedAndRecoveredByAHardTask) {
  // 0.5 ms cycles, every 10th 1 ms longer than the 1 ms budget: 100 cycles, 10 overruns.
  auto s =
      run("  - {name: load, module: cpu_load, period: 10ms, wcet: 1ms, "
          "params: {exec: 0.0005, overrun_every: 10, overrun: 0.001, recover: true}}\n",
          1000 * kMs);
  ASSERT_TRUE(s);
  const auto t = task(*s, "load");
  EXPECT_EQ(t.stats.cycles, 100u);
  EXPECT_EQ(t.stats.overruns, 10u);
  EXPECT_EQ(t.stats.missed, 0u);  // 1.5 ms ends well before the 10 ms deadline
  EXPECT_EQ(t.state, TaskState::kOn);
  // error() recovered each time; the operator hears of the 1st, 2nd, 4th and 8th.
  const std::string events = events_text(*s);
  EXPECT_NE(events.find("load: overran its wcet budget; error() recovered; timing faults so far: 1\n"),
            std::string::npos)
      << events;
  EXPECT_NE(events.find("timing faults so far: 8\n"), std::string::npos) << events;
  EXPECT_EQ(events.find("timing faults so far: 3\n"), std::string::npos) << events;
}

TEST(TimingFailures, AHardTaskThatDoesNotRecoverGoesToError) {
  auto s =
      run("  - {name: load, module: cpu_load, period: 10ms, wcet: 1ms, "
          "params: {exec: 0.0005, overrun_every: 10, overrun: 0.001}}\n"
          "  - {name: other, module: counter, period: 10ms}\n",
          1000 * kMs);
  ASSERT_TRUE(s);
  const auto t = task(*s, "load");
  EXPECT_EQ(t.state, TaskState::kError);
  EXPECT_EQ(t.stats.cycles, 10u);
  EXPECT_EQ(t.stats.overruns, 1u);
  EXPECT_TRUE(s->hard_task_failed());
  EXPECT_EQ(task(*s, "other").stats.cycles, 100u) << "the rest runs on";
  EXPECT_NE(events_text(*s).find("load: ERROR: operator intervention required (clear): overran its wcet budget"),
            std::string::npos);
}

TEST(TimingFailures, ASoftTaskOnlyCountsItsOverruns) {
  auto s =
      run("  - {name: load, module: cpu_load, period: 10ms, wcet: 1ms, criticality: soft, "
          "params: {exec: 0.0005, overrun_every: 5, overrun: 0.001}}\n",
          1000 * kMs);
  ASSERT_TRUE(s);
  const auto t = task(*s, "load");
  EXPECT_EQ(t.state, TaskState::kOn);
  EXPECT_EQ(t.stats.overruns, 20u);
  EXPECT_FALSE(s->hard_task_failed());
}

TEST(TimingFailures, DeadlineMissesOfAHardTaskRunLateAndAreAllCounted) {
  // Every 10th cycle takes 15.5 ms of a 10 ms period: it misses, and the next release runs late
  // (late: run, the default for hard tasks) but still within its own deadline. 1045 ms hold
  // 105 releases, and the 100th cycle (released at 990 ms, ended at 1005.5 ms) is the 10th miss.
  auto s =
      run("  - {name: load, module: cpu_load, period: 10ms, "
          "params: {exec: 0.0005, overrun_every: 10, overrun: 0.015, recover: true}}\n",
          1045 * kMs);
  ASSERT_TRUE(s);
  const auto t = task(*s, "load");
  EXPECT_EQ(t.stats.missed, 10u);
  EXPECT_EQ(t.stats.skipped, 0u);
  EXPECT_EQ(t.stats.cycles, 105u) << "late: run keeps every release";
  EXPECT_EQ(t.stats.latency_max_ns, 5'500'000) << "the release after a long cycle starts 5.5 ms late";
  EXPECT_EQ(t.stats.response_max_ns, 15'500'000);
}

TEST(TimingFailures, ASoftTaskSkipsReleasesWhoseDeadlineHasPassed) {
  // Every 10th cycle takes 25.5 ms: the next release's deadline (20 ms) has passed when the CPU
  // is free, so it is skipped (late: skip, the default for soft tasks); the one after runs late.
  // In 1045 ms (105 releases) the long cycles start at 90, 200, ... 970 ms: 9 of them, each
  // missing and skipping one release.
  auto s =
      run("  - {name: load, module: cpu_load, period: 10ms, criticality: soft, "
          "params: {exec: 0.0005, overrun_every: 10, overrun: 0.025}}\n",
          1045 * kMs);
  ASSERT_TRUE(s);
  const auto t = task(*s, "load");
  EXPECT_EQ(t.stats.skipped, 9u);
  EXPECT_EQ(t.stats.missed, 18u);
  EXPECT_EQ(t.stats.cycles, 96u);
  EXPECT_EQ(t.state, TaskState::kOn);
}

TEST(TimingFailures, LateRunIsTheSoftTasksChoiceToo) {
  auto s =
      run("  - {name: load, module: cpu_load, period: 10ms, criticality: soft, late: run, "
          "params: {exec: 0.0005, overrun_every: 10, overrun: 0.025}}\n",
          1000 * kMs);
  ASSERT_TRUE(s);
  EXPECT_EQ(task(*s, "load").stats.skipped, 0u);
}

TEST(TimingFailures, AHardTaskWhoseErrorHandlerFailsGoesToErrorAtItsFirstMiss) {
  auto s = run("  - {name: slow, module: tracer, period: 10ms, deadline: 2ms, virtual_exec: 3ms}\n", 100 * kMs);
  ASSERT_TRUE(s);
  const auto t = task(*s, "slow");
  EXPECT_EQ(t.state, TaskState::kError);
  EXPECT_EQ(t.stats.cycles, 1u);
  EXPECT_EQ(t.stats.missed, 1u);
}

}  // namespace
}  // namespace chimera
