// The KDL chain read from sim/models/arm6.urdf is the arm MuJoCo simulates from
// sim/models/arm6.xml: the same joints and limits, forward kinematics of the tool that agrees with
// MuJoCo's own kinematics of the site "tool", and a Jacobian that agrees with finite differences
// of the simulation.

#include "kinematics/arm_chain.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/sim/arm_sim.hpp"
#include "kinematics/pose.hpp"
#include "support/allocation_guard.hpp"

namespace chimera::kinematics {
namespace {

struct Arm {
  std::unique_ptr<ArmChain> chain;
  std::unique_ptr<sim::ArmSim> sim;
  int tool = -1;
};

Arm load_both() {
  Arm arm;
  auto chain = ArmChain::load("");
  EXPECT_TRUE(chain.ok()) << (chain.ok() ? "" : chain.error().message);
  auto sim = sim::ArmSim::load("");
  EXPECT_TRUE(sim.ok()) << (sim.ok() ? "" : sim.error().message);
  if (!chain.ok() || !sim.ok()) return arm;
  arm.chain = std::move(chain).value();
  arm.sim = std::move(sim).value();
  auto tool = arm.sim->find_site("tool");
  EXPECT_TRUE(tool.ok());
  arm.tool = tool.ok() ? *tool : -1;
  return arm;
}

Pose mujoco_tool_pose(Arm& arm, const std::vector<double>& q) {
  arm.sim->set_state(q, {});
  const sim::SitePose s = arm.sim->site_pose(arm.tool);
  Pose p;
  p.position = Eigen::Vector3d(s.position[0], s.position[1], s.position[2]);
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c)
      p.rotation(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = s.rotation[3 * r + c];
  return p;
}

// Joint positions spread over the whole range of every joint, the same on every run.
std::vector<std::vector<double>> sample_postures(const ArmChain& chain, int count) {
  std::vector<std::vector<double>> out;
  std::uint64_t state = 12345;
  const auto uniform = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11U) / 9007199254740992.0;
  };
  for (int k = 0; k < count; ++k) {
    std::vector<double> q;
    for (int i = 0; i < chain.ndof(); ++i) {
      const auto j = static_cast<std::size_t>(i);
      q.push_back(chain.lower()[j] + uniform() * (chain.upper()[j] - chain.lower()[j]));
    }
    out.push_back(q);
  }
  return out;
}

TEST(ArmChain, HasTheJointsAndLimitsOfTheMuJoCoModel) {
  Arm arm = load_both();
  ASSERT_TRUE(arm.chain && arm.sim);
  ASSERT_EQ(arm.chain->ndof(), arm.sim->ndof());
  const std::vector<std::string> names{"waist", "shoulder", "elbow", "wrist_roll", "wrist_pitch", "flange"};
  EXPECT_EQ(arm.chain->joint_names(), names);
  for (int i = 0; i < arm.chain->ndof(); ++i) {
    const auto j = static_cast<std::size_t>(i);
    EXPECT_DOUBLE_EQ(arm.chain->lower()[j], arm.sim->joint_min(i)) << names[j];
    EXPECT_DOUBLE_EQ(arm.chain->upper()[j], arm.sim->joint_max(i)) << names[j];
  }
}

TEST(ArmChain, ForwardKinematicsAgreesWithMuJoCosToolSite) {
  Arm arm = load_both();
  ASSERT_TRUE(arm.chain && arm.sim);
  double worst_position = 0.0;
  double worst_orientation = 0.0;
  for (const auto& q : sample_postures(*arm.chain, 500)) {
    const Pose kdl = arm.chain->forward(q);
    const Pose mujoco = mujoco_tool_pose(arm, q);
    const Vector6 e = pose_error(mujoco, kdl);
    worst_position = std::max(worst_position, position_norm(e));
    worst_orientation = std::max(worst_orientation, orientation_norm(e));
  }
  std::cout << "FK (KDL) vs MuJoCo over 500 postures: worst position error " << worst_position
            << " m, worst orientation error " << worst_orientation << " rad\n";
  RecordProperty("fk_worst_position_error_m", std::to_string(worst_position));
  EXPECT_LT(worst_position, 1e-12);
  EXPECT_LT(worst_orientation, 1e-12);
}

TEST(ArmChain, TheZeroPostureIsThePumaLikeShapeOfTheModel) {
  Arm arm = load_both();
  ASSERT_TRUE(arm.chain);
  // Upper arm along +x (0.432 m), forearm up: the tool 0.6 + 0.06 + 0.38 + 0.052 + 0.056 + 0.06 above
  // the floor, shoulder offset 0.15 - 0.05 to the side, pointing up.
  const Pose p = arm.chain->forward(std::vector<double>(6, 0.0));
  EXPECT_NEAR(p.position.x(), 0.432, 1e-15);
  EXPECT_NEAR(p.position.y(), 0.10, 1e-15);
  EXPECT_NEAR(p.position.z(), 1.208, 1e-15);
  EXPECT_TRUE(p.rotation.isApprox(Eigen::Matrix3d::Identity(), 1e-15));
}

// The Jacobian's columns are the tool's velocity per unit joint velocity: the same as the finite
// differences of the simulated tool site, moving one joint at a time.
TEST(ArmChain, JacobianAgreesWithFiniteDifferencesOfTheSimulation) {
  Arm arm = load_both();
  ASSERT_TRUE(arm.chain && arm.sim);
  constexpr double kH = 1e-6;
  double worst = 0.0;
  for (const auto& q : sample_postures(*arm.chain, 100)) {
    Pose pose;
    JacobianMatrix jacobian(6, 6);
    arm.chain->evaluate(q, pose, jacobian);
    for (int i = 0; i < 6; ++i) {
      auto plus = q;
      auto minus = q;
      plus[static_cast<std::size_t>(i)] += kH;
      minus[static_cast<std::size_t>(i)] -= kH;
      // Central differences: the pose error between the two neighbours, over the step.
      const Vector6 column = pose_error(mujoco_tool_pose(arm, plus), mujoco_tool_pose(arm, minus)) / (2 * kH);
      worst = std::max(worst, (column - jacobian.col(i)).cwiseAbs().maxCoeff());
    }
  }
  std::cout << "Jacobian (KDL) vs central differences of MuJoCo's tool site: worst entry error " << worst << "\n";
  EXPECT_LT(worst, 1e-7);
}

TEST(ArmChain, ForwardAndEvaluateAgree) {
  Arm arm = load_both();
  ASSERT_TRUE(arm.chain);
  const std::vector<double> q{0.3, -0.4, 1.1, 0.5, -0.9, 2.0};
  Pose pose;
  JacobianMatrix jacobian(6, 6);
  arm.chain->evaluate(q, pose, jacobian);
  const Pose alone = arm.chain->forward(q);
  EXPECT_EQ(pose.position, alone.position);
  EXPECT_EQ(pose.rotation, alone.rotation);
}

#if CHIMERA_ALLOCATION_GUARD  // plain builds: a sanitizer brings its own allocator
TEST(ArmChain, ForwardKinematicsAndJacobianDoNotAllocate) {
  auto chain = ArmChain::load("");
  ASSERT_TRUE(chain.ok());
  const std::vector<double> q{0.3, -0.4, 1.1, 0.5, -0.9, 2.0};
  Pose pose;
  JacobianMatrix jacobian(6, 6);
  long allocations = 0;
  {
    testing::AllocationGuard guard;
    for (int k = 0; k < 100; ++k) {
      (*chain)->evaluate(q, pose, jacobian);
      pose = (*chain)->forward(q);
    }
    allocations = testing::AllocationGuard::count();
  }
  EXPECT_EQ(allocations, 0);
}
#endif

TEST(ArmChain, AMissingUrdfNamesThePath) {
  auto r = ArmChain::load("/nonexistent/arm.urdf");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("/nonexistent/arm.urdf"), std::string::npos) << r.error().message;
}

TEST(ArmChain, AnUnknownLinkIsNamed) {
  auto r = ArmChain::load("", "base", "gripper");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("no link 'gripper'"), std::string::npos) << r.error().message;
  auto reversed = ArmChain::load("", "tool", "base");
  ASSERT_FALSE(reversed.ok());
  EXPECT_NE(reversed.error().message.find("is not below link 'tool'"), std::string::npos) << reversed.error().message;
}

TEST(ArmChain, ASubChainHasItsOwnJoints) {
  // From the forearm to the tool: the three wrist joints only.
  auto r = ArmChain::load("", "forearm", "tool");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ((*r)->ndof(), 3);
  const Pose p = (*r)->forward(std::vector<double>(3, 0.0));
  EXPECT_NEAR(p.position.z(), 0.38 + 0.052 + 0.056 + 0.06, 1e-15);
}

}  // namespace
}  // namespace chimera::kinematics
