// fwd_kin_jacobian in a running subsystem: its ports as contract section 3 gives them, x_m equal
// to the simulated arm's own tool pose, the Jacobian laid out row-major and equal to finite
// differences of the simulation, and clear failures for a chain that does not fit.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/sim/arm_sim.hpp"
#include "kinematics/pose.hpp"
#include "module_harness.hpp"
#include "support/port_contract.hpp"

namespace chimera::test {
namespace {

CHIMERA_REGISTER_MODULE(ScriptedSource);

using kinematics::Pose;
using kinematics::Vector6;

constexpr const char* kFile = R"(subsystem: fk_test
constants: { ndof: [6] }
tasks:
  - { name: joints, module: scripted_source, period: 1ms, params: { port: theta_m, size: 6 } }
  - { name: fk, module: fwd_kin_jacobian, period: 1ms }
)";

Pose sim_tool_pose(sim::ArmSim& arm, const std::vector<double>& q) {
  arm.set_state(q, {});
  const sim::SitePose s = arm.site_pose(*arm.find_site("tool"));
  Pose p;
  p.position = Eigen::Vector3d(s.position[0], s.position[1], s.position[2]);
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c)
      p.rotation(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = s.rotation[3 * r + c];
  return p;
}

TEST(FwdKinJacobian, PortsFollowTheContract) {
  expect_ports("fwd_kin_jacobian", {{"ndof", PortKind::kInConst, "1"},
                                    {"theta_m", PortKind::kInVar, "ndof"},
                                    {"x_m", PortKind::kOutVar, "6"},
                                    {"jacobian", PortKind::kOutVar, "6*ndof"}});
}

TEST(FwdKinJacobian, PoseAndJacobianAreTheSimulatedArmsOwn) {
  auto arm = sim::ArmSim::load("");
  ASSERT_TRUE(arm.ok());
  const std::vector<std::vector<double>> postures{
      {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, {0.3, -0.4, 1.1, 0.5, -0.9, 2.0}, {-2.0, 1.2, -1.9, 3.0, 1.5, -4.0}};
  ScriptedSource::set("joints", postures[0]);
  auto sub = start_subsystem(kFile);
  ASSERT_NE(sub, nullptr);
  for (const auto& q : postures) {
    ScriptedSource::set("joints", q);
    sub->run_for(2 * kMs);
    const auto x_m = value_of(*sub, "x_m");
    const auto jacobian = value_of(*sub, "jacobian");
    ASSERT_EQ(x_m.size(), 6U);
    ASSERT_EQ(jacobian.size(), 36U);
    const Vector6 e = kinematics::pose_error(sim_tool_pose(**arm, q), kinematics::pose_from(x_m));
    EXPECT_LT(e.norm(), 1e-12) << "posture " << q[0];
    // Row-major, rows vx vy vz wx wy wz: element r * ndof + c is d(twist_r) / d(theta_c).
    constexpr double kH = 1e-6;
    for (std::size_t c = 0; c < 6; ++c) {
      auto plus = q;
      auto minus = q;
      plus[c] += kH;
      minus[c] -= kH;
      const Vector6 column = kinematics::pose_error(sim_tool_pose(**arm, plus), sim_tool_pose(**arm, minus)) / (2 * kH);
      for (std::size_t r = 0; r < 6; ++r)
        EXPECT_NEAR(jacobian[r * 6 + c], column[static_cast<Eigen::Index>(r)], 1e-7) << "row " << r << " col " << c;
    }
  }
}

TEST(FwdKinJacobian, FollowsTheArmOfARunningRobotInterface) {
  // The interface publishes theta_m; x_m follows the arm wherever the servo takes it.
  const char* text = R"(subsystem: fk_robot
tasks:
  - { name: target, module: scripted_source, period: 1ms, params: { port: theta_d, size: 6 } }
  - { name: fk, module: fwd_kin_jacobian, period: 1ms }
  - { name: robot, module: robot_position, period: 1ms, params: { initial: [0.2, 0.1, 0.9, 0.0, 0.7, 0.0] } }
)";
  ScriptedSource::set("target", {0.5, -0.2, 1.2, 0.4, 0.9, -0.3});
  auto sub = start_subsystem(text);
  ASSERT_NE(sub, nullptr);
  auto arm = sim::ArmSim::load("");
  ASSERT_TRUE(arm.ok());
  for (int k = 0; k < 10; ++k) {
    sub->run_for(50 * kMs);
    const auto q = value_of(*sub, "theta_m");
    const auto x_m = value_of(*sub, "x_m");
    ASSERT_EQ(q.size(), 6U);
    // fk runs after the robot at each instant (the data-flow order): this instant's posture.
    EXPECT_LT(kinematics::pose_error(sim_tool_pose(**arm, q), kinematics::pose_from(x_m)).norm(), 1e-12);
  }
}

TEST(FwdKinJacobian, AChainWithAnotherNumberOfJointsDoesNotStart) {
  // From the base to the wrist pitch link: 5 joints, but ndof is 6.
  const std::string text = replaced(kFile, "module: fwd_kin_jacobian, period: 1ms }",
                                    "module: fwd_kin_jacobian, period: 1ms, params: { tip: wrist_pitch } }");
  EXPECT_NE(start_error(text).find("has 5 joints, but ndof is 6"), std::string::npos) << start_error(text);
}

TEST(FwdKinJacobian, AMissingUrdfIsNamed) {
  const std::string text = replaced(kFile, "module: fwd_kin_jacobian, period: 1ms }",
                                    "module: fwd_kin_jacobian, period: 1ms, params: { urdf: /nonexistent/arm.urdf } }");
  EXPECT_NE(start_error(text).find("/nonexistent/arm.urdf"), std::string::npos) << start_error(text);
}

}  // namespace
}  // namespace chimera::test
