// The illegal-configuration flag against its raisers on real threads (and under TSAN): a task
// entering ERROR on its own thread while a switch holds the flag, and while switches commit. The
// flag is a count of holds (a task in ERROR, a switch under way, a hard job overdue), changed by
// atomic increments, so no interleaving lowers it while one of them lasts; these tests force the
// interleavings that used to lower it (a scan of the tasks, then a store of the verdict, with a
// task entering ERROR in between).

#include <atomic>
#include <chrono>
#include <future>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/probe_module.hpp"
#include "support/run_subsystem.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

// Blocks in init until the test opens it: a switch that creates it is held under way.
std::atomic<bool> g_gate_open{false};  // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): the test's latch
std::atomic<bool> g_gate_waiting{false};  // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): as above

class Gate final : public Module {
 public:
  static constexpr const char* kName = "gate";
  static constexpr const char* kSummary = "init waits for the test";
  static constexpr const char* kDoc = "";
  static void declare(Declarations& d, const Params& /*p*/) { d.out_var("gate_out", Dim::fixed(1), "nothing"); }

 protected:
  Status init(InitContext& /*ctx*/) override {
    g_gate_waiting.store(true);
    for (int i = 0; i < 10'000 && !g_gate_open.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return Status::ok();
  }
};

Registry& registry() {
  static Registry r = [] {
    Registry reg;
    (void)reg.add(testing::info_of<testing::Probe>());
    (void)reg.add(testing::info_of<testing::Counter>());
    (void)reg.add(testing::info_of<Gate>());
    return reg;
  }();
  return r;
}

template <class Predicate>
bool eventually(Predicate p) {
  for (int i = 0; i < 5'000; ++i) {
    if (p()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return p();
}

TaskState state_of(Subsystem& s, const std::string& task) { return testing::task_of(s, task).state; }

// `faulty` fails in its cycle after 500 cycles and does not recover: ERROR on its own thread. Late
// enough that the switch (refused once a task is in ERROR) is under way first, even in a TSAN build.
const std::string kGated = R"(subsystem: flagrace
tasks:
  - {name: faulty, module: probe, period: 1ms, criticality: soft, params: {fail: cycle, fail_after: 500}}
  - {name: gate, module: gate, period: 1ms, criticality: soft}
configurations:
  plain: [faulty]
  gated: [faulty, gate]
)";

// `a` and `b` take turns; each fails in its first cycle after a few: they enter ERROR on their
// own threads right after a switch turned them on, while the switch finishes.
const std::string kTurns = R"(subsystem: flagturns
tasks:
  - {name: a, module: probe, period: 1ms, criticality: soft, params: {fail: cycle, fail_after: 3},
     rename: {probe_count: a_count}}
  - {name: b, module: probe, period: 1ms, criticality: soft, params: {fail: cycle, fail_after: 3},
     rename: {probe_count: b_count}}
  - {name: keep, module: counter, period: 1ms, criticality: soft}
configurations:
  with_a: [a, keep]
  with_b: [b, keep]
)";

TEST(FlagRace, ATaskEnteringErrorWhileASwitchIsUnderWayKeepsTheFlagUpAfterIt) {
  g_gate_open = false;
  g_gate_waiting = false;
  auto s = testing::start_subsystem(kGated, registry(), ClockKind::kReal);
  ASSERT_TRUE(s);
  // The switch to `gated` must create the gate: it holds the flag until it commits, and the gate's
  // init keeps it from committing until the test says so.
  auto switching = std::async(std::launch::async, [&] { return s->switch_to("gated"); });
  ASSERT_TRUE(eventually([] { return g_gate_waiting.load(); }));
  EXPECT_TRUE(s->illegal_configuration()) << "held by the switch";
  // Meanwhile `faulty` fails on its own thread and enters ERROR.
  ASSERT_TRUE(eventually([&] { return state_of(*s, "faulty") == TaskState::kError; }));
  g_gate_open = true;
  const auto record = switching.get();
  ASSERT_TRUE(record.ok()) << record.error().message;
  EXPECT_TRUE(record->flag_raised);
  // The switch gave back its hold; the task in ERROR still holds the flag.
  EXPECT_TRUE(s->illegal_configuration()) << "lowered by the switch while a task is in ERROR";
  ASSERT_TRUE(s->signal("faulty", Signal::kClear).ok());
  EXPECT_FALSE(s->illegal_configuration()) << "nothing holds it any more";
}

TEST(FlagRace, TasksFailingOnTheirThreadsWhileSwitchesCommitNeverLoseTheFlag) {
  auto s = testing::start_subsystem(kTurns, registry(), ClockKind::kReal);
  ASSERT_TRUE(s);
  int seen_in_error = 0;
  for (int i = 0; i < 150; ++i) {
    const std::string target = s->configuration() == "with_a" ? "with_b" : "with_a";
    const std::string joining = target == "with_a" ? "a" : "b";
    if (state_of(*s, joining) == TaskState::kError) {
      ASSERT_TRUE(s->signal(joining, Signal::kClear).ok());
    }
    auto r = s->switch_to(target);
    ASSERT_TRUE(r.ok()) << r.error().message;
    // Right after the commit, while the joining task's first cycles run (and fail) on its thread.
    for (int look = 0; look < 20; ++look) {
      // The states first, then the flag: a task shows ERROR only once it holds the flag.
      const bool in_error = state_of(*s, "a") == TaskState::kError || state_of(*s, "b") == TaskState::kError;
      const bool raised = s->illegal_configuration();
      if (in_error) ++seen_in_error;
      EXPECT_TRUE(!in_error || raised) << "switch " << i << ": a task in ERROR, and the flag down";
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
  EXPECT_GT(seen_in_error, 100) << "the failures never overlapped the switches: the test proved nothing";
  for (const char* t : {"a", "b"}) {
    if (state_of(*s, t) == TaskState::kError) {
      ASSERT_TRUE(s->signal(t, Signal::kClear).ok());
    }
  }
  EXPECT_FALSE(s->illegal_configuration()) << "nothing holds it any more";
}

}  // namespace
}  // namespace chimera
