// Every lifecycle transition of Figure 7, and each module method failing in turn (by returning
// a failure and by throwing), run through a Subsystem on the virtual clock.

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/probe_module.hpp"

namespace chimera {
namespace {

using testing::calls;
using testing::kClear;
using testing::kCycle;
using testing::kError;
using testing::kInit;
using testing::kKill;
using testing::kOff;
using testing::kOn;

constexpr std::int64_t kMs = 1'000'000;

/// A subsystem with one probe `p` (params given as YAML flow text) and one healthy counter `c`.
std::unique_ptr<Subsystem> make(const std::string& probe_params, bool start = true) {
  calls().clear();
  const std::string text =
      "subsystem: life\ntasks:\n"
      "  - {name: p, module: probe, period: 1ms, params: " +
      probe_params +
      "}\n"
      "  - {name: c, module: counter, period: 1ms}\n";
  auto spec = load_subsystem_text(text, "life.yaml", testing::test_registry());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  RunOptions o;
  o.clock = ClockKind::kVirtual;
  o.shm_suffix = testing::unique_suffix();
  auto s = Subsystem::create(*spec, testing::test_registry(), o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  if (start) {
    EXPECT_TRUE((*s)->start().ok());
  }
  return std::move(*s);
}

TaskState state_of(const Subsystem& s, const std::string& name) {
  for (const auto& t : s.snapshot())
    if (t.name == name) return t.state;
  ADD_FAILURE() << "no task " << name;
  return TaskState::kNotCreated;
}
std::uint64_t cycles_of(const Subsystem& s, const std::string& name) {
  for (const auto& t : s.snapshot())
    if (t.name == name) return t.stats.cycles;
  return 0;
}
bool any_event_contains(Subsystem& s, const std::string& text) {
  bool found = false;
  for (const auto& e : s.drain_events()) found = found || e.text.find(text) != std::string::npos;
  return found;
}

TEST(TaskLifecycle, HappyPathThroughEveryState) {
  auto s = make("{}", /*start=*/false);
  EXPECT_EQ(state_of(*s, "p"), TaskState::kNotCreated);
  ASSERT_TRUE(s->signal("p", Signal::kSpawn).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kOff);
  EXPECT_EQ(calls()["p"][kInit], 1);
  ASSERT_TRUE(s->signal("p", Signal::kOn).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kOn);
  s->run_for(10 * kMs);
  EXPECT_EQ(cycles_of(*s, "p"), 10u);
  // Out-vars are pushed after every method: the probe's count is visible in the global table.
  EXPECT_EQ(s->get("probe_count")->at(0), 10.0);
  ASSERT_TRUE(s->signal("p", Signal::kOff).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kOff);
  s->run_for(10 * kMs);
  EXPECT_EQ(cycles_of(*s, "p"), 10u) << "an OFF task does not cycle";
  ASSERT_TRUE(s->signal("p", Signal::kKill).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kNotCreated);
  EXPECT_EQ(calls()["p"][kOn], 1);
  EXPECT_EQ(calls()["p"][kOff], 1);
  EXPECT_EQ(calls()["p"][kKill], 1);
  EXPECT_EQ(calls()["p"][kError], 0);
}

TEST(TaskLifecycle, KillOfAnOnTaskCallsOffThenKill) {
  auto s = make("{}");
  ASSERT_TRUE(s->signal("p", Signal::kKill).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kNotCreated);
  EXPECT_EQ(calls()["p"][kOff], 1);
  EXPECT_EQ(calls()["p"][kKill], 1);
}

TEST(TaskLifecycle, SignalsTheStateDoesNotAllowAreRefusedAndChangeNothing) {
  auto s = make("{}", false);
  EXPECT_FALSE(s->signal("p", Signal::kOn).ok());
  EXPECT_FALSE(s->signal("p", Signal::kOff).ok());
  EXPECT_FALSE(s->signal("p", Signal::kClear).ok());
  EXPECT_FALSE(s->signal("p", Signal::kKill).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kNotCreated);
  ASSERT_TRUE(s->signal("p", Signal::kSpawn).ok());
  const auto refused = s->signal("p", Signal::kSpawn);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("cannot spawn a task that is OFF"), std::string::npos);
  EXPECT_FALSE(s->signal("p", Signal::kClear).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kOff);
  EXPECT_EQ(calls()["p"][kInit], 1);
  EXPECT_FALSE(s->signal("nosuch", Signal::kOn).ok());
}

class FailingMethod : public ::testing::TestWithParam<bool> {};  // param: throw instead of return

TEST_P(FailingMethod, InitFailureCallsKillAndLeavesTheTaskNotCreated) {
  auto s = make(std::string("{fail: init, throw: ") + (GetParam() ? "true" : "false") + "}", false);
  const auto r = s->signal("p", Signal::kSpawn);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(GetParam() ? "probe threw in init" : "probe failed on purpose"), std::string::npos)
      << r.error().message;
  EXPECT_EQ(state_of(*s, "p"), TaskState::kNotCreated);
  EXPECT_EQ(calls()["p"][kKill], 1) << "the paper: an error in init calls kill";
  EXPECT_EQ(calls()["p"][kError], 0) << "error() is not called for an init failure";
}

TEST_P(FailingMethod, CycleFailureNotRecoveredGoesToErrorAndTheRestRunsOn) {
  auto s = make(std::string("{fail: cycle, fail_after: 5, throw: ") + (GetParam() ? "true" : "false") + "}");
  s->run_for(20 * kMs);
  EXPECT_EQ(state_of(*s, "p"), TaskState::kError);
  EXPECT_EQ(cycles_of(*s, "p"), 6u) << "five good cycles, the failing one, then no more";
  EXPECT_EQ(calls()["p"][kError], 1);
  EXPECT_EQ(cycles_of(*s, "c"), 20u) << "a module's fault stops only its own task";
  EXPECT_TRUE(s->hard_task_failed());
  EXPECT_TRUE(any_event_contains(*s, "ERROR"));
  bool reported = false;
  for (const auto& t : s->snapshot())
    if (t.name == "p") reported = !t.last_error.empty();
  EXPECT_TRUE(reported) << "the subsystem interface is told";
}

TEST_P(FailingMethod, CycleFailureRecoveredByErrorKeepsTheTaskOn) {
  auto s = make(std::string("{fail: cycle, recover: true, throw: ") + (GetParam() ? "true" : "false") + "}");
  s->run_for(10 * kMs);
  EXPECT_EQ(state_of(*s, "p"), TaskState::kOn);
  EXPECT_EQ(cycles_of(*s, "p"), 10u);
  EXPECT_EQ(calls()["p"][kError], 10);
  EXPECT_FALSE(s->hard_task_failed());
}

TEST_P(FailingMethod, OnFailure) {
  auto s = make(std::string("{fail: on, recover: true, throw: ") + (GetParam() ? "true" : "false") + "}", false);
  ASSERT_TRUE(s->signal("p", Signal::kSpawn).ok());
  EXPECT_FALSE(s->signal("p", Signal::kOn).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kOff) << "recovered: the task stays OFF";
  auto t = make(std::string("{fail: on, throw: ") + (GetParam() ? "true" : "false") + "}", false);
  ASSERT_TRUE(t->signal("p", Signal::kSpawn).ok());
  EXPECT_FALSE(t->signal("p", Signal::kOn).ok());
  EXPECT_EQ(state_of(*t, "p"), TaskState::kError) << "not recovered: ERROR";
}

TEST_P(FailingMethod, OffFailure) {
  auto s = make(std::string("{fail: off, recover: true, throw: ") + (GetParam() ? "true" : "false") + "}");
  EXPECT_TRUE(s->signal("p", Signal::kOff).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kOff);
  auto t = make(std::string("{fail: off, throw: ") + (GetParam() ? "true" : "false") + "}");
  EXPECT_FALSE(t->signal("p", Signal::kOff).ok());
  EXPECT_EQ(state_of(*t, "p"), TaskState::kError);
}

TEST_P(FailingMethod, KillFailureStillDestroysTheTask) {
  auto s = make(std::string("{fail: kill, throw: ") + (GetParam() ? "true" : "false") + "}");
  const auto r = s->signal("p", Signal::kKill);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kNotCreated);
  EXPECT_TRUE(s->signal("p", Signal::kSpawn).ok()) << "and it can be spawned again";
}

INSTANTIATE_TEST_SUITE_P(ReturnOrThrow, FailingMethod, ::testing::Bool());

TEST(TaskLifecycle, ClearReturnsToOffOnlyWhenClearReportsTheFaultGone) {
  auto s = make("{fail: cycle, clear_ok: false}");
  s->run_for(2 * kMs);
  ASSERT_EQ(state_of(*s, "p"), TaskState::kError);
  EXPECT_FALSE(s->signal("p", Signal::kOn).ok()) << "ERROR accepts only clear and kill";
  EXPECT_FALSE(s->signal("p", Signal::kClear).ok());
  EXPECT_EQ(state_of(*s, "p"), TaskState::kError);
  EXPECT_EQ(calls()["p"][kClear], 1);

  auto t = make("{fail: cycle}");
  t->run_for(2 * kMs);
  ASSERT_EQ(state_of(*t, "p"), TaskState::kError);
  EXPECT_TRUE(t->signal("p", Signal::kClear).ok());
  EXPECT_EQ(state_of(*t, "p"), TaskState::kOff);
  EXPECT_TRUE(t->signal("p", Signal::kOn).ok());
  EXPECT_EQ(state_of(*t, "p"), TaskState::kOn);
}

TEST(TaskLifecycle, StartIsAllOrNothing) {
  calls().clear();
  const std::string text =
      "subsystem: life\ntasks:\n"
      "  - {name: a, module: counter, period: 1ms}\n"
      "  - {name: p, module: probe, period: 1ms, params: {fail: init}}\n";
  auto spec = load_subsystem_text(text, "life.yaml", testing::test_registry());
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  RunOptions o;
  o.clock = ClockKind::kVirtual;
  o.shm_suffix = testing::unique_suffix();
  auto s = Subsystem::create(*spec, testing::test_registry(), o);
  ASSERT_TRUE(s.ok());
  EXPECT_FALSE((*s)->start().ok());
  for (const auto& t : (*s)->snapshot()) EXPECT_EQ(t.state, TaskState::kNotCreated) << t.name << ": no partial start";
}

TEST(TaskLifecycle, StopTurnsEverythingOffThenKills) {
  auto s = make("{}");
  s->stop();
  EXPECT_EQ(calls()["p"][kOff], 1);
  EXPECT_EQ(calls()["p"][kKill], 1);
  s->stop();  // idempotent
  EXPECT_EQ(calls()["p"][kKill], 1);
}

TEST(TaskLifecycle, OperatorSetIsRefusedForAProducedVariable) {
  auto s = make("{}");
  const auto refused = s->set("count", {5});
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("task 'c'"), std::string::npos) << refused.error().message;
  ASSERT_TRUE(s->signal("c", Signal::kOff).ok());
  ASSERT_TRUE(s->set("count", {5}).ok());
  EXPECT_EQ(s->get("count")->at(0), 5.0);
  EXPECT_FALSE(s->set("count", {1, 2}).ok()) << "wrong count";
  EXPECT_FALSE(s->set("count", {1.5}).ok()) << "not a whole number for i64";
}

TEST(TaskLifecycle, AFailureIsOneEventAndLastErrorIsCurrentWithoutDraining) {
  auto s = make("{fail: cycle}");
  s->run_for(2 * kMs);
  for (const auto& t : s->snapshot()) {
    if (t.name == "p") {
      EXPECT_NE(t.last_error.find("probe failed on purpose"), std::string::npos) << t.last_error;
    }
  }
  const auto events = s->drain_events();
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].text, "cycle failed: probe failed on purpose");
  EXPECT_EQ(events[1].text, "ERROR: operator intervention required (clear): probe failed on purpose");
}

TEST(TaskLifecycle, AfterStopFiguresRemainAndCommandsAreRefused) {
  auto s = make("{}");
  s->run_for(5 * kMs);
  s->stop();
  const auto snap = s->snapshot();
  ASSERT_EQ(snap.size(), 2u);
  EXPECT_EQ(snap[0].stats.cycles, 5u);
  EXPECT_EQ(snap[0].state, TaskState::kNotCreated);
  EXPECT_FALSE(s->get("count").ok());
  EXPECT_FALSE(s->set("count", {1}).ok());
  EXPECT_FALSE(s->signal("p", Signal::kSpawn).ok());
  EXPECT_EQ(s->now_ns(), 5 * kMs);
}

}  // namespace
}  // namespace chimera
