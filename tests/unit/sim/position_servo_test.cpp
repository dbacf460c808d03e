// The arm's own position servo (ArmSim's position drive, behind robot_position): it holds the
// arm against gravity, moves its reference toward a target no faster than max_speed, settles on
// the target, respects the joint ranges, repeats exactly, and allocates nothing while it runs.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/sim/arm_sim.hpp"
#include "support/allocation_guard.hpp"

namespace chimera::sim {
namespace {

constexpr std::int64_t kMs = 1'000'000;

std::unique_ptr<ArmSim> load_arm() {
  auto r = ArmSim::load("");
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? std::move(r).value() : nullptr;
}

double max_abs_difference(std::span<const double> a, std::span<const double> b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::fabs(a[i] - b[i]));
  return worst;
}

TEST(PositionServo, HoldsTheArmAgainstGravity) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  // Upper arm out horizontally, forearm forward: the posture gravity pulls on hardest.
  const std::vector<double> q0{0.3, 0.0, 1.2, 0.0, 0.5, 0.0};
  arm->set_state(q0, {});
  arm->set_drive(Drive::kPosition);
  EXPECT_EQ(arm->drive(), Drive::kPosition);
  for (int k = 0; k < 2000; ++k) arm->step(kMs);
  // The feed-forward of the model's gravity leaves nothing for the PD to correct.
  EXPECT_LT(max_abs_difference(arm->positions(), q0), 1e-9);
  // The same posture under torque control with zero torque falls.
  auto falling = load_arm();
  ASSERT_NE(falling, nullptr);
  falling->set_state(q0, {});
  for (int k = 0; k < 200; ++k) falling->step(kMs);
  EXPECT_GT(max_abs_difference(falling->positions(), q0), 0.05);
}

TEST(PositionServo, TheReferenceRespectsSpeedAndAccelerationAndStopsOnTheTarget) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  arm->set_drive(Drive::kPosition);
  const std::vector<double> target{0.8, 0.5, -0.6, 1.0, 0.9, -1.2};
  arm->set_position_target(target);
  const ServoGains& g = arm->servo();
  std::vector<double> previous_speed(6, 0.0);
  double fastest = 0.0;
  double worst_lag = 0.0;
  for (int k = 1; k <= 1500; ++k) {
    arm->step(kMs);
    for (std::size_t i = 0; i < 6; ++i) {
      const double speed = arm->reference_speed()[i];
      ASSERT_LE(std::fabs(speed), g.max_speed[i] + 1e-12) << "joint " << i << " at " << k << " ms";
      ASSERT_LE(std::fabs(speed - previous_speed[i]), g.max_acceleration[i] * 1e-3 + 1e-9) << "joint " << i;
      // Straight there: never past the target (but for the rounding of one step of acceleration),
      // never backwards.
      ASSERT_LE(arm->position_reference()[i] * std::copysign(1.0, target[i]),
                std::fabs(target[i]) + g.max_acceleration[i] * 1e-6);
      ASSERT_GE(speed * std::copysign(1.0, target[i]), -g.max_acceleration[i] * 1e-3)
          << "joint " << i << " at " << k << " ms";
      previous_speed[i] = speed;
      fastest = std::max(fastest, std::fabs(arm->velocities()[i]));
      worst_lag = std::max(worst_lag, std::fabs(arm->positions()[i] - arm->position_reference()[i]));
    }
  }
  std::cout << "servo: a step of up to 1.2 rad; the arm within " << worst_lag << " rad of its reference, fastest joint "
            << fastest << " rad/s, 1.5 s later " << max_abs_difference(arm->positions(), target)
            << " rad from the target\n";
  EXPECT_LT(max_abs_difference(arm->positions(), target), 1e-6);
  // The servo feeds the reference motion's inverse dynamics forward: the arm follows it closely.
  EXPECT_LT(worst_lag, 5e-4);
  EXPECT_LT(fastest, 1.05 * kDefaultServoMaxSpeed);
}

TEST(PositionServo, FollowsAMovingTargetWithoutLag) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  arm->set_drive(Drive::kPosition);
  std::vector<double> target(6);
  double worst = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double t = 1e-3 * k;
    for (std::size_t i = 0; i < 6; ++i) {
      const double phase = static_cast<double>(i);
      target[i] = 0.4 * (std::sin(2.0 * t + phase) - std::sin(phase));
    }
    // Where the arm is now against where it is asked to be now; then the next period.
    if (k > 1000) worst = std::max(worst, max_abs_difference(arm->positions(), target));
    arm->set_position_target(target);
    arm->step(kMs);
  }
  std::cout << "servo: following 0.4 rad sines at 0.8 rad/s, worst error after 1 s " << worst << " rad\n";
  EXPECT_LT(worst, 1e-4);  // an eighth of one period's motion (0.8 rad/s * 1 ms)
}

TEST(PositionServo, GainsForABandwidthAreCriticallyDampedOnEachJointsInertia) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  const ServoGains g = arm->servo_gains(5.0, 2.0);
  const double w = 2.0 * std::numbers::pi * 5.0;
  ASSERT_EQ(g.kp.size(), 6U);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_GT(g.kp[i], 0.0);
    EXPECT_NEAR(g.kd[i] * g.kd[i], 4.0 * g.kp[i] * g.kp[i] / (w * w), 1e-9 * g.kp[i] * g.kp[i]);  // kd = 2 m w
    EXPECT_DOUBLE_EQ(g.max_speed[i], 2.0);
  }
  // The waist turns the whole arm; the flange only the tool.
  EXPECT_GT(g.kp[0], 5.0 * g.kp[5]);
  // Half the motor's torque accelerates the joint's own inertia: m = kp / w^2.
  EXPECT_NEAR(g.max_acceleration[1], 0.5 * 150.0 / (g.kp[1] / (w * w)), 1e-9);
  EXPECT_NEAR(g.max_acceleration[5], 0.5 * 20.0 / (g.kp[5] / (w * w)), 1e-9);
  // A new arm's servo is the default bandwidth's.
  const ServoGains d = arm->servo_gains(kDefaultServoBandwidthHz, kDefaultServoMaxSpeed);
  EXPECT_EQ(arm->servo().kp, d.kp);
  EXPECT_EQ(arm->servo().kd, d.kd);
}

TEST(PositionServo, ASmallStepSettlesWithoutOvershoot) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  arm->set_gravity({0.0, 0.0, 0.0});
  ServoGains step = arm->servo_gains(10.0, 100.0);  // no ramp: a true step
  step.max_acceleration.assign(6, 1e6);
  ASSERT_TRUE(arm->set_servo_gains(step).ok());
  arm->set_drive(Drive::kPosition);
  const std::vector<double> target{0.0, 0.0, 0.0, 0.0, 0.01, 0.0};
  arm->set_position_target(target);
  double peak = 0.0;
  for (int k = 0; k < 500; ++k) {
    arm->step(kMs);
    peak = std::max(peak, arm->positions()[4]);
  }
  EXPECT_NEAR(arm->positions()[4], 0.01, 1e-6);
  EXPECT_LT(peak, 0.0102);  // critically damped: at most a trace of overshoot from the coupling
}

TEST(PositionServo, TargetsAreClampedIntoTheJointRanges) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  arm->set_drive(Drive::kPosition);
  const std::vector<double> beyond{10.0, -10.0, 10.0, -10.0, 10.0, std::nan("")};
  arm->set_position_target(beyond);
  EXPECT_DOUBLE_EQ(arm->position_target()[0], arm->joint_max(0));
  EXPECT_DOUBLE_EQ(arm->position_target()[1], arm->joint_min(1));
  EXPECT_DOUBLE_EQ(arm->position_target()[4], 1.75);
  EXPECT_DOUBLE_EQ(arm->position_target()[5], 0.0);  // NaN ignored: the target stays
}

TEST(PositionServo, SwitchingFromTorqueHoldsWhereTheArmIs) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  for (int k = 0; k < 150; ++k) arm->step(kMs);  // falling under gravity, no torque
  const std::vector<double> there(arm->positions().begin(), arm->positions().end());
  ASSERT_GT(std::fabs(arm->velocities()[1]), 0.1);
  arm->set_drive(Drive::kPosition);
  EXPECT_EQ(max_abs_difference(arm->position_target(), there), 0.0);
  for (int k = 0; k < 1000; ++k) arm->step(kMs);
  // Caught while falling: brought back to where it was at the switch, and held there.
  EXPECT_LT(max_abs_difference(arm->positions(), there), 1e-4);
  for (const double v : arm->velocities()) EXPECT_LT(std::fabs(v), 1e-3);
  // And back to torque mode: the servo lets go.
  arm->set_drive(Drive::kTorque);
  arm->set_torque({});
  for (int k = 0; k < 150; ++k) arm->step(kMs);
  EXPECT_GT(max_abs_difference(arm->positions(), there), 0.05);
}

std::vector<double> servo_run(ArmSim& arm) {
  std::vector<double> trace;
  arm.set_drive(Drive::kPosition);
  std::vector<double> target(6);
  for (int k = 0; k < 1000; ++k) {
    for (std::size_t i = 0; i < 6; ++i) target[i] = 0.5 * std::sin(0.003 * k + static_cast<double>(i));
    arm.set_position_target(target);
    arm.step(kMs);
    trace.insert(trace.end(), arm.positions().begin(), arm.positions().end());
  }
  return trace;
}

TEST(PositionServo, IdenticalRunsGiveIdenticalStates) {
  auto a = load_arm();
  auto b = load_arm();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(servo_run(*a), servo_run(*b));  // bit for bit
}

TEST(PositionServo, RefusesBadGains) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  ServoGains g = arm->servo();
  g.kp.pop_back();
  EXPECT_FALSE(arm->set_servo_gains(g).ok());
  g = arm->servo();
  g.kd[2] = -1.0;
  EXPECT_FALSE(arm->set_servo_gains(g).ok());
  g = arm->servo();
  g.max_speed[0] = 0.0;
  EXPECT_FALSE(arm->set_servo_gains(g).ok());
  g = arm->servo();
  g.max_acceleration[3] = -2.0;
  EXPECT_FALSE(arm->set_servo_gains(g).ok());
}

TEST(PositionServo, ReportsTheToolSitePose) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  auto tool = arm->find_site("tool");
  ASSERT_TRUE(tool.ok()) << tool.error().message;
  EXPECT_FALSE(arm->find_site("gripper").ok());
  // Zero posture: upper arm along +x, forearm up, tool pointing up.
  const SitePose p = arm->site_pose(*tool);
  EXPECT_NEAR(p.position[0], 0.432, 1e-12);
  EXPECT_NEAR(p.position[1], 0.10, 1e-12);
  EXPECT_NEAR(p.position[2], 1.208, 1e-12);
  EXPECT_NEAR(p.rotation[0], 1.0, 1e-12);
  EXPECT_NEAR(p.rotation[8], 1.0, 1e-12);
  // After steps the pose is that of the present joints, not of the state before the last step:
  // the same as an arm put at those joint positions.
  arm->set_state(std::vector<double>{0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, std::vector<double>{1.0, 0, 0, 0, 2.0, 0});
  for (int k = 0; k < 10; ++k) arm->step(kMs);
  const SitePose moved = arm->site_pose(*tool);
  auto still = load_arm();
  ASSERT_NE(still, nullptr);
  still->set_state(arm->positions(), {});
  const SitePose there = still->site_pose(*tool);
  EXPECT_GT(std::fabs(moved.position[1] - p.position[1]), 1e-3);  // it did move
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(moved.position[i], there.position[i], 1e-15);
  for (std::size_t i = 0; i < 9; ++i) EXPECT_NEAR(moved.rotation[i], there.rotation[i], 1e-15);
}

#if CHIMERA_ALLOCATION_GUARD  // plain builds: a sanitizer brings its own allocator
TEST(PositionServo, DoesNotAllocate) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  auto tool = arm->find_site("tool");
  ASSERT_TRUE(tool.ok());
  const std::vector<double> target{0.2, 0.1, 0.3, 0.0, 0.4, 0.0};
  long allocations = 0;
  {
    testing::AllocationGuard guard;
    arm->set_drive(Drive::kPosition);
    for (int k = 0; k < 100; ++k) {
      arm->set_position_target(target);
      arm->step(kMs);
      volatile double sink = arm->site_pose(*tool).position[0];
      (void)sink;
    }
    arm->set_drive(Drive::kTorque);
    allocations = testing::AllocationGuard::count();
  }
  EXPECT_EQ(allocations, 0);
}
#endif

}  // namespace
}  // namespace chimera::sim
