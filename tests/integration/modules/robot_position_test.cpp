// robot_position in a running subsystem: its ports; the arm following a joint trajectory through
// the servo inside the simulation, stepped in lockstep with the task's period; a jump in theta_d
// made smooth within max_speed; its parameters; runs that repeat exactly.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "module_harness.hpp"
#include "support/port_contract.hpp"

namespace chimera::test {
namespace {

CHIMERA_REGISTER_MODULE(ScriptedSource);

double max_abs_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) worst = std::max(worst, std::fabs(a[i] - b[i]));
  return worst;
}

constexpr const char* kTrajectory = R"(subsystem: position_traj
tasks:
  - { name: traj, module: joint_traj_gen, period: 1ms }
  - { name: robot, module: robot_position, period: 1ms }
)";

constexpr const char* kStep = R"(subsystem: position_step
tasks:
  - { name: goal, module: scripted_source, period: 1ms, params: { port: theta_d, size: 6 } }
  - { name: robot, module: robot_position, period: 1ms, params: { initial: [0, 0, 0, 0, 0, 0] } }
)";

TEST(RobotPosition, PortsFollowTheContract) {
  expect_ports("robot_position", {{"theta_d", PortKind::kInVar, "6"},
                                  {"theta_m", PortKind::kOutVar, "6"},
                                  {"dtheta_m", PortKind::kOutVar, "6"},
                                  {"ndof", PortKind::kOutConst, "1"}});
  const Declarations d = Registry::global().find("robot_position")->declarations(Params{});
  EXPECT_FALSE(d.resource().empty());
}

TEST(RobotPosition, TheArmFollowsAJointTrajectory) {
  auto sub = start_subsystem(kTrajectory);
  ASSERT_NE(sub, nullptr);
  EXPECT_EQ(value_of(*sub, "ndof"), std::vector<double>{6.0});
  double worst = 0.0;
  double moved = 0.0;
  const auto start = value_of(*sub, "theta_m");
  for (int k = 0; k < 500; ++k) {
    sub->run_for(10 * kMs);
    // After an instant's cycles theta_m is where the arm is one period later (the robot has
    // stepped the simulation); compare it with what the trajectory asks for at that next instant.
    const auto theta_m = value_of(*sub, "theta_m");
    sub->run_for(kMs);
    const auto theta_d = value_of(*sub, "theta_d");
    worst = std::max(worst, max_abs_difference(theta_d, theta_m));
    moved = std::max(moved, max_abs_difference(theta_m, start));
  }
  std::cout << "robot_position following joint_traj_gen for 5.5 s: worst error " << worst << " rad\n";
  EXPECT_GT(moved, 1.0);   // the default motion swings joints by more than a radian
  EXPECT_LT(worst, 1e-4);  // the servo follows a smooth theta_d without lag
  EXPECT_EQ(sub->now_ns(), 5500 * kMs);
  for (const auto& t : sub->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name << ": " << t.last_error;
}

TEST(RobotPosition, AJumpBecomesASmoothMoveWithinMaxSpeed) {
  const std::vector<double> goal{1.0, -0.5, 0.8, 2.0, -1.0, 1.5};
  ScriptedSource::set("goal", goal);
  auto sub =
      start_subsystem(replaced(kStep, "initial: [0, 0, 0, 0, 0, 0]", "initial: [0, 0, 0, 0, 0, 0], max_speed: [1.5]"));
  ASSERT_NE(sub, nullptr);
  double fastest = 0.0;
  for (int k = 0; k < 2500; ++k) {
    sub->run_for(kMs);
    for (const double v : value_of(*sub, "dtheta_m")) fastest = std::max(fastest, std::fabs(v));
  }
  std::cout << "a jump of up to 2 rad at max_speed 1.5 rad/s: fastest joint " << fastest << " rad/s\n";
  EXPECT_LT(fastest, 1.5 * 1.02);
  EXPECT_GT(fastest, 1.4);  // and it did go at about that speed
  EXPECT_LT(max_abs_difference(value_of(*sub, "theta_m"), goal), 1e-6);
}

TEST(RobotPosition, TheSimulationStepsInLockstepWithThePeriod) {
  // A 5 ms period moves the arm by 5 physics steps a cycle: the same motion as at 1 ms, sampled.
  const std::vector<double> goal{0.3, 0.2, 0.1, 0.0, 0.0, 0.0};
  ScriptedSource::set("goal", goal);
  auto fast = start_subsystem(kStep);
  auto slow = start_subsystem(replaced(replaced(kStep, "period: 1ms, params: { port", "period: 5ms, params: { port"),
                                       "module: robot_position, period: 1ms", "module: robot_position, period: 5ms"));
  ASSERT_TRUE(fast && slow);
  for (int k = 0; k < 40; ++k) {
    fast->run_for(5 * kMs);
    slow->run_for(5 * kMs);
    // The same target all along: the arm's own servo does the same steps either way.
    EXPECT_EQ(value_of(*fast, "theta_m"), value_of(*slow, "theta_m")) << "at " << 5 * (k + 1) << " ms";
  }
}

TEST(RobotPosition, TwoRunsAreBitIdentical) {
  const auto run = [] {
    std::vector<double> trace;
    auto sub =
        start_subsystem(replaced(kTrajectory, "module: robot_position, period: 1ms }",
                                 "module: robot_position, period: 1ms, params: { noise_std: 0.001, seed: 4 } }"));
    if (!sub) return trace;
    for (int k = 0; k < 100; ++k) {
      sub->run_for(10 * kMs);
      const auto q = value_of(*sub, "theta_m");
      trace.insert(trace.end(), q.begin(), q.end());
    }
    return trace;
  };
  const auto a = run();
  ASSERT_EQ(a.size(), 600U);
  EXPECT_EQ(a, run());
}

TEST(RobotPosition, BadParametersAreNamed) {
  ScriptedSource::set("goal", std::vector<double>(6, 0.0));
  EXPECT_NE(start_error(replaced(kStep, "initial: [0, 0, 0, 0, 0, 0]", "initial: [0, 0, 0, 0, 0, 0], bandwidth: 0"))
                .find("params.bandwidth: 0 given: must be > 0"),
            std::string::npos);
  EXPECT_NE(
      start_error(replaced(kStep, "initial: [0, 0, 0, 0, 0, 0]", "initial: [0, 0, 0, 0, 0, 0], max_speed: [1, 2]"))
          .find("max_speed and max_acceleration need ndof"),
      std::string::npos);
  EXPECT_NE(
      start_error(replaced(kStep, "initial: [0, 0, 0, 0, 0, 0]", "initial: [0, 0, 0]")).find("parameter initial has 3"),
      std::string::npos);
  EXPECT_NE(start_error(replaced(kStep, "initial: [0, 0, 0, 0, 0, 0]",
                                 "initial: [0, 0, 0, 0, 0, 0], model: /nonexistent/arm.xml"))
                .find("/nonexistent/arm.xml"),
            std::string::npos);
}

}  // namespace
}  // namespace chimera::test
