// inv_kin in a running subsystem: its ports, round trips along a path of poses continued from
// cycle to cycle, the joint limits (its own and the URDF's), the posture it starts from, and the
// closed loop with the position-mode robot.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kinematics_fixture.hpp"
#include "module_harness.hpp"
#include "support/port_contract.hpp"

namespace chimera::test {
namespace {

CHIMERA_REGISTER_MODULE(ScriptedSource);

constexpr const char* kFile = R"(subsystem: ik_test
constants: { ndof: [6] }
tasks:
  - { name: goal, module: scripted_source, period: 1ms, params: { port: x_d, size: 6 } }
  - { name: joints, module: scripted_source, period: 1ms, params: { port: theta_m, size: 6 } }
  - { name: ik, module: inv_kin, period: 1ms }
)";

TEST(InvKin, PortsFollowTheContract) {
  expect_ports("inv_kin", {{"ndof", PortKind::kInConst, "1"},
                           {"x_d", PortKind::kInVar, "6"},
                           {"theta_m", PortKind::kInVar, "ndof"},
                           {"theta_d", PortKind::kOutVar, "ndof"}});
}

TEST(InvKin, StartsFromTheMeasuredPostureAndRoundTripsAlongAPath) {
  std::vector<double> truth{0.1, -0.2, 0.9, 0.3, 0.8, -0.4};
  ScriptedSource::set("joints", truth);
  ScriptedSource::set("goal", tool_pose(truth));
  auto sub = start_subsystem(kFile);
  ASSERT_NE(sub, nullptr);
  // Turned on, it publishes where the arm is: nothing moves.
  EXPECT_EQ(value_of(*sub, "theta_d"), truth);
  // A random walk of postures, 0.1 rad a step on every joint; each pose solved within a cycle
  // from the previous solution.
  std::uint64_t state = 99;
  double worst = 0.0;
  for (int k = 0; k < 200; ++k) {
    for (std::size_t i = 0; i < 6; ++i) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      const double step = 0.2 * (static_cast<double>(state >> 11U) / 9007199254740992.0 - 0.5);
      truth[i] = std::clamp(truth[i] + step, -1.2, 1.2);
    }
    truth[2] = std::clamp(truth[2], 0.3, 1.3);  // away from the elbow's singular postures
    truth[4] = std::clamp(truth[4], 0.3, 1.3);  // and from the straight wrist
    ScriptedSource::set("goal", tool_pose(truth));
    sub->run_for(kMs);
    const auto theta_d = value_of(*sub, "theta_d");
    ASSERT_EQ(theta_d.size(), 6U);
    worst = std::max(worst, pose_difference(tool_pose(theta_d), tool_pose(truth)).norm());
  }
  std::cout << "inv_kin along a random path of 200 poses, one cycle each: worst pose error " << worst << "\n";
  EXPECT_LT(worst, 1e-8);
}

TEST(InvKin, KeepsWithinItsJointLimits) {
  // The pose needs the elbow at 1.0 rad; this task may bend it only to 0.6.
  const std::vector<double> truth{0.2, 0.3, 1.0, 0.4, 0.8, -0.2};
  ScriptedSource::set("joints", {0.2, 0.3, 0.5, 0.4, 0.8, -0.2});
  ScriptedSource::set("goal", tool_pose(truth));
  const std::string text =
      replaced(kFile, "module: inv_kin, period: 1ms }",
               "module: inv_kin, period: 1ms, params: { upper: [2.79, 1.75, 0.6, 4.6, 1.75, 4.6] } }");
  auto sub = start_subsystem(text);
  ASSERT_NE(sub, nullptr);
  sub->run_for(50 * kMs);
  const auto theta_d = value_of(*sub, "theta_d");
  ASSERT_EQ(theta_d.size(), 6U);
  EXPECT_DOUBLE_EQ(theta_d[2], 0.6);
  const auto& chain = shipped_chain();
  for (std::size_t i = 0; i < 6; ++i) EXPECT_GE(theta_d[i], chain.lower()[i]) << i;
  // The best the limit allows: nearer than the true posture with its elbow merely clamped.
  auto clamped = truth;
  clamped[2] = 0.6;
  EXPECT_LT(kinematics::position_norm(pose_difference(tool_pose(theta_d), tool_pose(truth))),
            kinematics::position_norm(pose_difference(tool_pose(clamped), tool_pose(truth))));
}

TEST(InvKin, AnUnreachablePoseLeavesTheJointsWithinTheUrdfLimits) {
  ScriptedSource::set("joints", {0.0, 0.2, 0.6, 0.0, 0.5, 0.0});
  ScriptedSource::set("goal", {2.5, 0.1, 0.7, 0.0, 2.356, 0.0});  // 2.5 m out: far beyond reach
  auto sub = start_subsystem(kFile);
  ASSERT_NE(sub, nullptr);
  sub->run_for(200 * kMs);
  const auto theta_d = value_of(*sub, "theta_d");
  ASSERT_EQ(theta_d.size(), 6U);
  const auto& chain = shipped_chain();
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_TRUE(std::isfinite(theta_d[i]));
    EXPECT_GE(theta_d[i], chain.lower()[i]);
    EXPECT_LE(theta_d[i], chain.upper()[i]);
  }
  // Stretched out toward it: the elbow straight (pi/2) to within a few hundredths.
  EXPECT_NEAR(theta_d[2], 1.5708, 0.05);
}

TEST(InvKin, DrivesThePositionModeRobotOntoThePose) {
  const char* text = R"(subsystem: ik_robot
tasks:
  - { name: goal, module: scripted_source, period: 1ms, params: { port: x_d, size: 6 } }
  - { name: ik, module: inv_kin, period: 1ms }
  - { name: robot, module: robot_position, period: 1ms, params: { initial: [0.0, -0.2, 0.7, 0.0, 1.4, 0.0] } }
  - { name: fk, module: fwd_kin_jacobian, period: 1ms }
)";
  const std::vector<double> goal{0.80, 0.25, 0.85, 0.3, 2.2, 0.1};
  ScriptedSource::set("goal", goal);
  auto sub = start_subsystem(text);
  ASSERT_NE(sub, nullptr);
  sub->run_for(2000 * kMs);
  const auto x_m = value_of(*sub, "x_m");
  ASSERT_EQ(x_m.size(), 6U);
  const auto e = pose_difference(goal, x_m);
  EXPECT_LT(kinematics::position_norm(e), 1e-6);
  EXPECT_LT(kinematics::orientation_norm(e), 1e-6);
}

TEST(InvKin, BadLimitsDoNotStart) {
  ScriptedSource::set("joints", std::vector<double>(6, 0.0));
  ScriptedSource::set("goal", tool_pose(std::vector<double>(6, 0.0)));
  EXPECT_NE(start_error(replaced(kFile, "module: inv_kin, period: 1ms }",
                                 "module: inv_kin, period: 1ms, params: { lower: [1, 1], upper: [2, 2] } }"))
                .find("lower and upper need ndof"),
            std::string::npos);
  EXPECT_NE(start_error(replaced(kFile, "module: inv_kin, period: 1ms }",
                                 "module: inv_kin, period: 1ms, params: { lower: [1], upper: [0] } }"))
                .find("a lower joint limit is above its upper one"),
            std::string::npos);
}

}  // namespace
}  // namespace chimera::test
