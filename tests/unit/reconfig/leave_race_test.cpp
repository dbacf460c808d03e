// A switch's leaving task that fails (ERROR) after it was told to leave and before the commit:
// the switch must not wait for a release the task no longer runs.
//
// The leave is a mail the task's thread answers after the task's last release before the commit.
// The thread reads its mail at the top of a pass, then runs the releases that are due. A task
// whose release k was due but not yet run when the mail came (its thread delayed behind a
// higher-priority task on its CPU) reads the leave, defers it to its release k+1 (the commit's),
// runs k, and fails in it. It used to never answer: no ERROR task runs a release. The switch
// waited 10 s for it and reported "a: no answer within 10 s (a method is stuck?)" (seen once in
// ctest, FlagRace, while other tests loaded the machine).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "chimera/control/subsystem.hpp"
#include "support/probe_module.hpp"
#include "support/run_subsystem.hpp"

namespace chimera {
namespace {

std::atomic<bool> g_fail_now{false};  // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): the test's switch

// Fails its cycle when the test says so.
class FailsWhenTold final : public Module {
 public:
  static constexpr const char* kName = "fails_when_told";
  static constexpr const char* kSummary = "a cycle fails when the test says so";
  static constexpr const char* kDoc = "";
  static void declare(Declarations& d, const Params& /*p*/) { d.out_var("told_out", Dim::fixed(1), "nothing"); }

 protected:
  Status cycle() override { return g_fail_now.load() ? Status::fail("told to fail") : Status::ok(); }
};

// Takes 400 us of every 500 us period: at each whole millisecond it runs first on its CPU
// (rate monotonic: the shorter period), and a 1 ms task's release waits behind it.
class Hog final : public Module {
 public:
  static constexpr const char* kName = "hog";
  static constexpr const char* kSummary = "busy 400 us a cycle";
  static constexpr const char* kDoc = "";
  static void declare(Declarations& d, const Params& /*p*/) { d.out_var("hog_out", Dim::fixed(1), "nothing"); }

 protected:
  Status cycle() override {
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(400);
    while (std::chrono::steady_clock::now() < until) {
    }
    return Status::ok();
  }
};

Registry& registry() {
  static Registry r = [] {
    Registry reg;
    (void)reg.add(testing::info_of<FailsWhenTold>());
    (void)reg.add(testing::info_of<Hog>());
    (void)reg.add(testing::info_of<testing::Counter>());
    return reg;
  }();
  return r;
}

const std::string kFile = R"(subsystem: leaverace
tasks:
  - {name: hog, module: hog, period: 500us, criticality: soft, cpu: 0}
  - {name: a, module: fails_when_told, period: 1ms, criticality: soft, cpu: 0}
  - {name: b, module: counter, period: 1ms, criticality: soft, cpu: 0}
configurations:
  with_a: [hog, a]
  with_b: [hog, b]
start: with_a
)";

std::uint64_t cycles_of(Subsystem& s, const std::string& task) { return testing::task_of(s, task).stats.cycles; }

TEST(LeaveRace, ALeavingTaskThatFailsBeforeTheCommitStillAnswersTheSwitch) {
  g_fail_now = false;
  auto s = testing::start_subsystem(kFile, registry(), ClockKind::kReal);
  ASSERT_TRUE(s);
  constexpr int kAttempts = 12;
  for (int i = 0; i < kAttempts; ++i) {
    ASSERT_EQ(s->configuration(), "with_a");
    ASSERT_EQ(testing::task_of(*s, "a").state, TaskState::kOn) << "attempt " << i;
    // a's cycle k has just run (some 400 us after the millisecond k, behind the hog): the next
    // millisecond comes in about 600 us, and a's release there waits 400 us behind the hog.
    // Told to fail and to leave inside that wait, it takes the leave with the release still due.
    const std::uint64_t seen = cycles_of(*s, "a");
    while (cycles_of(*s, "a") == seen) std::this_thread::yield();
    std::this_thread::sleep_for(std::chrono::microseconds(650));
    g_fail_now = true;
    const auto posted = std::chrono::steady_clock::now();
    auto r = s->switch_to("with_b");
    const auto took = std::chrono::steady_clock::now() - posted;
    EXPECT_TRUE(r.ok()) << "attempt " << i << ": " << r.error().message;
    EXPECT_LT(took, std::chrono::seconds(1)) << "attempt " << i << ": the switch waited for the failed task";
    if (!r.ok()) break;  // each such attempt costs 10 s
    // Back for the next attempt: a (ERROR now, or OFF if it left first) cleared and switched in.
    g_fail_now = false;
    if (testing::task_of(*s, "a").state == TaskState::kError) {
      ASSERT_TRUE(s->signal("a", Signal::kClear).ok());
    }
    auto back = s->switch_to("with_a");
    ASSERT_TRUE(back.ok()) << back.error().message;
  }
  EXPECT_GE(cycles_of(*s, "hog"), std::uint64_t{2 * kAttempts}) << "the hog ran (each attempt waits a millisecond or more)";
}

}  // namespace
}  // namespace chimera
