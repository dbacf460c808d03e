// teleop_input and cartesian_interp as tasks on the virtual clock: a recorded session carried out
// on time, the dead man's switch, the reach limit, UDP datagrams, refusals; the interpolation from
// where the tool is toward the goal; and the two chained, as in Figure 6.

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"
#include "support/probe_module.hpp"
#include "support/udp_sender.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;
// The measured pose the tests hold still: the tool at (0.5, 0, 0.5), turned 0.3 rad about z.
constexpr const char* kPose = "[0.5, 0, 0.5, 0, 0, 0.3]";

class TeleopTest : public ::testing::Test {
 protected:
  // `tasks` under constants x_m (and whatever `constants` adds), created and started on the
  // virtual clock; nullptr with the message in error_ if anything fails.
  std::unique_ptr<Subsystem> start(const std::string& tasks, const std::string& constants = {}) {
    auto spec = load_subsystem_text(
        "subsystem: teleop\nconstants:\n  x_m: " + std::string(kPose) + "\n" + constants + "tasks:\n" + tasks,
        "teleop.yaml", Registry::global());
    if (!spec) {
      error_ = spec.error().message;
      return nullptr;
    }
    specs_.push_back(std::make_unique<SubsystemSpec>(*std::move(spec)));
    RunOptions o;
    o.clock = ClockKind::kVirtual;
    o.shm_suffix = testing::unique_suffix();
    auto s = Subsystem::create(*specs_.back(), Registry::global(), o);
    if (!s) {
      error_ = s.error().message;
      return nullptr;
    }
    if (auto started = (*s)->start(); !started) {
      error_ = started.error().message;
      return nullptr;
    }
    return std::move(*s);
  }

  static std::vector<double> get(const Subsystem& s, const std::string& variable) {
    auto v = s.get(variable);
    EXPECT_TRUE(v.ok()) << variable;
    return v.ok() ? *v : std::vector<double>{};
  }

  static void expect_pose(const std::vector<double>& x, const std::array<double, 6>& expected, double tolerance,
                          const std::string& what) {
    ASSERT_EQ(x.size(), 6u) << what;
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(x[i], expected[i], tolerance) << what << ", element " << i;
  }

  std::vector<std::unique_ptr<SubsystemSpec>> specs_;
  std::string error_;
};

TEST_F(TeleopTest, ARecordedSessionIsCarriedOutOnTime) {
  auto s = start(
      "  - name: teleop\n    module: teleop_input\n    period: 10ms\n    params:\n      source: replay\n"
      "      session: ['0.05 move 0.1 0 0', '0.1 move 0 0.05 0 0 0 0.2', '# a comment', "
      "'0.2 goto 0.4 0.1 0.6 0 0 0', '0.3 home']\n");
  ASSERT_NE(s, nullptr) << error_;
  s->run_for(45 * kMs);  // cycles at 0..40 ms: nothing due yet
  expect_pose(get(*s, "x_goal"), {0.5, 0, 0.5, 0, 0, 0.3}, 1e-12, "the start: where the tool is");
  s->run_for(10 * kMs);  // the cycle at 50 ms
  expect_pose(get(*s, "x_goal"), {0.6, 0, 0.5, 0, 0, 0.3}, 1e-12, "after move 0.1 0 0");
  s->run_for(50 * kMs);
  expect_pose(get(*s, "x_goal"), {0.6, 0.05, 0.5, 0, 0, 0.5}, 1e-12, "after a step and a turn about z");
  s->run_for(100 * kMs);
  expect_pose(get(*s, "x_goal"), {0.4, 0.1, 0.6, 0, 0, 0}, 1e-12, "after goto");
  s->run_for(100 * kMs);
  expect_pose(get(*s, "x_goal"), {0.5, 0, 0.5, 0, 0, 0.3}, 1e-12, "after home");
  EXPECT_EQ(get(*s, "teleop_stats"), (std::vector<double>{4, 0, 0}));
}

TEST_F(TeleopTest, AVelocityStopsAtTheDeadMansTimeout) {
  auto s = start(
      "  - name: teleop\n    module: teleop_input\n    period: 10ms\n"
      "    params: { source: replay, timeout: 0.2, session: ['0 vel 0.1 0 0 0 0 0.5'] }\n");
  ASSERT_NE(s, nullptr) << error_;
  s->run_for(1000 * kMs);
  // It moves at the cycles from 0 to 0.2 s (21 of them, 10 ms each) and no more.
  expect_pose(get(*s, "x_goal"), {0.5 + 21 * 0.001, 0, 0.5, 0, 0, 0.3 + 21 * 0.005}, 1e-9, "stopped");
}

TEST_F(TeleopTest, TheGoalStaysWithinReach) {
  auto s = start(
      "  - name: teleop\n    module: teleop_input\n    period: 10ms\n"
      "    params: { source: replay, max_distance: 0.1, session: ['0 move 0.3 0.4 0'] }\n");
  ASSERT_NE(s, nullptr) << error_;
  s->run_for(5 * kMs);
  expect_pose(get(*s, "x_goal"), {0.5 + 0.06, 0.08, 0.5, 0, 0, 0.3}, 1e-12, "0.1 m along the commanded direction");
}

TEST_F(TeleopTest, DatagramsAreCommandsAndNonsenseIsCounted) {
  auto s = start("  - { name: teleop, module: teleop_input, period: 10ms }\n");
  ASSERT_NE(s, nullptr) << error_;
  s->run_for(5 * kMs);
  const auto stats = get(*s, "teleop_stats");
  ASSERT_EQ(stats.size(), 3u);
  ASSERT_GT(stats[2], 0) << "the port the system chose";

  const testing::UdpSender sender(static_cast<int>(stats[2]));
  // On loopback a datagram is in the socket when it is sent: the next cycle reads it.
  ASSERT_TRUE(sender.send("move 0.01 0 0\nmove 0.01 0 0\n"));
  ASSERT_TRUE(sender.send("jump"));
  ASSERT_TRUE(sender.send("move 0 0 -0.02 0 0 -0.3"));
  s->run_for(10 * kMs);
  expect_pose(get(*s, "x_goal"), {0.52, 0, 0.48, 0, 0, 0}, 1e-12, "three moves");
  EXPECT_EQ(get(*s, "teleop_stats"), (std::vector<double>{3, 1, stats[2]}));
}

TEST_F(TeleopTest, ABadSessionDoesNotStart) {
  for (const char* params : {"{ source: replay, session: ['0.5 jump 1 2 3'] }", "{ source: replay }",
                             "{ source: replay, session: ['1 stop', '0.5 stop'] }",
                             "{ source: replay, record: /no/such/file.txt }"}) {
    auto s = start(std::string("  - { name: teleop, module: teleop_input, period: 10ms, params: ") + params + " }\n");
    EXPECT_EQ(s, nullptr) << params;
    EXPECT_NE(error_.find("teleop_input: "), std::string::npos) << params << ": " << error_;
  }
  // An unknown source is refused by its declared choices, before init, with the line.
  auto s = start("  - { name: teleop, module: teleop_input, period: 10ms, params: { source: joystick } }\n");
  EXPECT_EQ(s, nullptr);
  EXPECT_NE(error_.find("params.source: \"joystick\" given: must be one of: udp, replay"), std::string::npos) << error_;
}

TEST_F(TeleopTest, TheInterpolationStartsWhereTheToolIsAndReachesTheGoal) {
  auto s =
      start("  - { name: interp, module: cartesian_interp, period: 1ms }\n", "  x_goal: [0.6, 0, 0.5, 0, 0, 0.3]\n");
  ASSERT_NE(s, nullptr) << error_;
  s->run_for(1 * kMs);
  const auto first = get(*s, "x_d");
  ASSERT_EQ(first.size(), 6u);
  EXPECT_GT(first[0], 0.5) << "moving";
  EXPECT_LT(first[0], 0.5 + 1e-5) << "from where the tool is, slowly";
  s->run_for(299 * kMs);
  const auto halfway = get(*s, "x_d");
  EXPECT_NEAR(get(*s, "dx_d")[0], 0.25, 1e-12) << "at the speed limit";
  EXPECT_LT(halfway[0], 0.6);
  s->run_for(700 * kMs);  // 0.1 m at 0.25 m/s and 1 m/s^2: 0.65 s
  expect_pose(get(*s, "x_d"), {0.6, 0, 0.5, 0, 0, 0.3}, 1e-12, "arrived");
  expect_pose(get(*s, "dx_d"), {0, 0, 0, 0, 0, 0}, 0.0, "at rest");
}

TEST_F(TeleopTest, TeleoperationThroughTheInterpolation) {
  auto s = start(
      "  - name: teleop\n    module: teleop_input\n    period: 10ms\n"
      "    params: { source: replay, session: ['0.1 move 0.05 0 0', '0.6 move 0 0 0.05 0 0 -0.3'] }\n"
      "  - { name: interp, module: cartesian_interp, period: 1ms }\n");
  ASSERT_NE(s, nullptr) << error_;
  s->run_for(100 * kMs);
  expect_pose(get(*s, "x_d"), {0.5, 0, 0.5, 0, 0, 0.3}, 1e-12, "no command yet: the tool holds");
  s->run_for(500 * kMs);
  expect_pose(get(*s, "x_d"), {0.55, 0, 0.5, 0, 0, 0.3}, 1e-12, "the first step done");
  s->run_for(1000 * kMs);
  expect_pose(get(*s, "x_d"), {0.55, 0, 0.55, 0, 0, 0}, 1e-12, "the second");
}

}  // namespace
}  // namespace chimera
