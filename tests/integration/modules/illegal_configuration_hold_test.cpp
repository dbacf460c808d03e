// The paper's illegal-configuration flag (section 3.4) and the robot interfaces' locally stable
// mode: while the flag is raised (through the global table, as a reconfiguration would), both
// robot_torque and robot_position ignore their inputs and hold the arm where it was when the
// flag rose; when it clears they take their inputs again and the controller's tracking resumes.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "control/subsystem_test_access.hpp"
#include "module_harness.hpp"

namespace chimera::test {
namespace {

double max_abs_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) worst = std::max(worst, std::fabs(a[i] - b[i]));
  return worst;
}

double max_abs(const std::vector<double>& v) {
  double worst = 0.0;
  for (const double x : v) worst = std::max(worst, std::fabs(x));
  return worst;
}

// Figure 4 (torque mode) and its position-mode counterpart, the same trajectory either way.
constexpr const char* kTorque = R"(subsystem: hold_torque
tasks:
  - { name: traj, module: joint_traj_gen, period: 1ms }
  - { name: pid, module: pid_joint, period: 1ms }
  - { name: robot, module: robot_torque, period: 1ms }
)";
constexpr const char* kPosition = R"(subsystem: hold_position
tasks:
  - { name: traj, module: joint_traj_gen, period: 1ms }
  - { name: robot, module: robot_position, period: 1ms }
)";

struct HoldFigures {
  double drift_while_held = 0.0;      // rad, worst |theta_m - theta_m at the flag| after 0.5 s held
  double speed_at_end_of_hold = 0.0;  // rad/s
  double trajectory_moved = 0.0;      // rad, how far theta_d went meanwhile (ignored by the robot)
  double error_after_resume = 0.0;    // rad, worst |theta_d - theta_m| in the last second
};

HoldFigures raise_and_clear(const std::string& text, double resume_tolerance) {
  HoldFigures out;
  auto sub = start_subsystem(text);
  if (!sub) return out;
  sub->run_for(1200 * kMs);  // in the middle of a move of the default trajectory
  EXPECT_GT(max_abs(value_of(*sub, "dtheta_m")), 0.3) << "the arm should be moving when the flag rises";
  SubsystemTestAccess::table(*sub).raise_illegal_configuration();
  sub->run_for(kMs);  // the next cycle of the interface sees the flag
  const auto held_at = value_of(*sub, "theta_m");
  const auto theta_d_at = value_of(*sub, "theta_d");
  sub->run_for(500 * kMs);  // braking to a stop, then still
  for (int k = 0; k < 150; ++k) {
    sub->run_for(10 * kMs);
    out.drift_while_held = std::max(out.drift_while_held, max_abs_difference(value_of(*sub, "theta_m"), held_at));
  }
  out.speed_at_end_of_hold = max_abs(value_of(*sub, "dtheta_m"));
  out.trajectory_moved = max_abs_difference(value_of(*sub, "theta_d"), theta_d_at);
  SubsystemTestAccess::table(*sub).lower_illegal_configuration();
  sub->run_for(3000 * kMs);
  for (int k = 0; k < 100; ++k) {
    sub->run_for(10 * kMs);
    out.error_after_resume =
        std::max(out.error_after_resume, max_abs_difference(value_of(*sub, "theta_d"), value_of(*sub, "theta_m")));
  }
  EXPECT_LT(out.error_after_resume, resume_tolerance);
  for (const auto& t : sub->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name << ": " << t.last_error;
  return out;
}

TEST(IllegalConfigurationHold, TheTorqueInterfaceHoldsWithGravityCompensationAndResumes) {
  const HoldFigures f = raise_and_clear(kTorque, 0.03);  // Figure 4's own tracking bound
  std::cout << "robot_torque: held within " << f.drift_while_held << " rad of where the flag rose (after braking), "
            << "speed " << f.speed_at_end_of_hold << " rad/s, while theta_d moved " << f.trajectory_moved
            << " rad; after resuming, tracking error " << f.error_after_resume << " rad\n";
  // The PD hold caught the moving arm and brought it back to where the flag rose.
  EXPECT_LT(f.drift_while_held, 0.005);
  EXPECT_LT(f.speed_at_end_of_hold, 1e-3);
  EXPECT_GT(f.trajectory_moved, 0.3);  // tau_r went on changing, and the arm took no notice
}

TEST(IllegalConfigurationHold, ThePositionInterfaceHoldsAndResumes) {
  const HoldFigures f = raise_and_clear(kPosition, 2e-3);
  std::cout << "robot_position: held within " << f.drift_while_held << " rad, speed " << f.speed_at_end_of_hold
            << " rad/s, while theta_d moved " << f.trajectory_moved << " rad; after resuming, tracking error "
            << f.error_after_resume << " rad\n";
  EXPECT_LT(f.drift_while_held, 0.005);
  EXPECT_LT(f.speed_at_end_of_hold, 1e-3);
  EXPECT_GT(f.trajectory_moved, 0.3);
}

TEST(IllegalConfigurationHold, HeldMeansStillOnceStopped) {
  // An arm at rest when the flag rises does not move at all, whatever theta_d does.
  for (const char* text : {kTorque, kPosition}) {
    auto sub = start_subsystem(text);
    ASSERT_NE(sub, nullptr);
    SubsystemTestAccess::table(*sub).raise_illegal_configuration();
    sub->run_for(kMs);
    const auto held_at = value_of(*sub, "theta_m");
    sub->run_for(3000 * kMs);  // the trajectory runs through two via points meanwhile
    EXPECT_LT(max_abs_difference(value_of(*sub, "theta_m"), held_at), 1e-6) << text;
    EXPECT_GT(max_abs_difference(value_of(*sub, "theta_d"), held_at), 0.3) << text;
  }
}

}  // namespace
}  // namespace chimera::test
