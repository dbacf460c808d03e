// The Cartesian interpolation law (modules/cartesian_interp/cartesian_motion.hpp): straight lines,
// the shortest rotation, speed and acceleration within their limits, no overshoot, the time a
// trapezoidal profile takes, and a goal that moves on the way.

#include "cartesian_interp/cartesian_motion.hpp"

#include <cmath>
#include <iomanip>

#include <gtest/gtest.h>

namespace chimera::modules::cartesian {
namespace {

constexpr double kDt = 0.001;

Pose at(double x, double y, double z, const Vec3& r = Vec3::Zero()) {
  return Pose{Vec3(x, y, z), kinematics::rotation_from_vector(r)};
}

TEST(CartesianMotion, ADisplacementAndTheRotationErrorUndoEachOther) {
  const Pose start = at(0.5, 0.1, 0.4, Vec3(0, 2.356, 0));
  const Vec3 dr(0.1, -0.2, 0.3);
  const Pose moved = displaced(start, Vec3(0.01, 0.02, -0.03), dr);
  EXPECT_LT((moved.position - Vec3(0.51, 0.12, 0.37)).norm(), 1e-15);
  EXPECT_LT((rotation_error(moved.rotation, start.rotation) - dr).norm(), 1e-12) << "turned by dr about the base axes";
}

TEST(CartesianMotion, AStepIsAStraightTrapezoidWithinTheLimits) {
  const Limits limits{0.25, 1.0, 1.0, 4.0};
  CartesianMotion m;
  const Pose start = at(0.5, 0.1, 0.4);
  const Pose goal = at(0.6, 0.05, 0.48);
  m.reset(start);
  const Vec3 line = (goal.position - start.position).normalized();
  Vec3 previous_velocity = Vec3::Zero();
  double peak = 0.0;
  double travelled_before = 0.0;
  int steps = 0;
  for (; steps < 5000 && (m.pose().position - goal.position).norm() > 0.0; ++steps) {
    m.step(goal, limits, kDt);
    const Vec3 from_start = m.pose().position - start.position;
    EXPECT_LT((from_start - from_start.dot(line) * line).norm(), 1e-12) << "off the line at step " << steps;
    EXPECT_LE(m.velocity().norm(), limits.speed + 1e-12);
    EXPECT_LE((m.velocity() - previous_velocity).norm(), limits.acceleration * kDt + 1e-12);
    EXPECT_GE(from_start.dot(line), travelled_before - 1e-12) << "it never goes back, step " << steps;
    EXPECT_LE(from_start.dot(line), (goal.position - start.position).norm() + 1e-12)
        << "no overshoot, step " << steps << std::setprecision(17) << " " << from_start.dot(line);
    travelled_before = from_start.dot(line);
    previous_velocity = m.velocity();
    peak = std::max(peak, m.velocity().norm());
  }
  EXPECT_EQ((m.pose().position - goal.position).norm(), 0.0) << "it stops on the goal";
  m.step(goal, limits, kDt);
  EXPECT_EQ(m.velocity().norm(), 0.0) << "and stands still";
  EXPECT_EQ((m.pose().position - goal.position).norm(), 0.0);
  EXPECT_NEAR(peak, limits.speed, 1e-12) << "a long enough move reaches the speed limit";
  // A trapezoid over d = 0.1375 m: d / v + v / a = 0.55 + 0.25 s, give or take a few steps.
  const double d = (goal.position - start.position).norm();
  EXPECT_NEAR(steps * kDt, d / limits.speed + limits.speed / limits.acceleration, 0.01);
}

TEST(CartesianMotion, AShortStepIsATriangle) {
  const Limits limits{0.25, 1.0, 1.0, 4.0};
  CartesianMotion m;
  m.reset(at(0, 0, 0));
  const Pose goal = at(0.01, 0, 0);
  double peak = 0.0;
  int steps = 0;
  for (; steps < 5000 && m.pose().position != goal.position; ++steps) {
    m.step(goal, limits, kDt);
    peak = std::max(peak, m.velocity().norm());
  }
  // Accelerate to the middle and brake: peak speed sqrt(a d) = 0.1 m/s, time 2 sqrt(d / a) = 0.2 s.
  EXPECT_NEAR(peak, 0.1, 0.002);
  EXPECT_NEAR(steps * kDt, 0.2, 0.005);
}

TEST(CartesianMotion, TheOrientationTurnsAboutOneAxisWithinItsLimits) {
  const Limits limits{0.25, 1.0, 0.5, 2.0};
  CartesianMotion m;
  const Pose start = at(0.5, 0, 0.5, Vec3(0, 2.356, 0));
  m.reset(start);
  const Pose goal =
      at(0.5, 0, 0.5, kinematics::rotation_vector(kinematics::rotation_from_vector(Vec3(0, 0, 0.6)) * start.rotation));
  Vec3 previous = Vec3::Zero();
  int steps = 0;
  for (; steps < 10000 && rotation_error(goal.rotation, m.pose().rotation).norm() > 1e-12; ++steps) {
    m.step(goal, limits, kDt);
    EXPECT_LE(m.angular_velocity().norm(), limits.angular_speed + 1e-12);
    EXPECT_LE((m.angular_velocity() - previous).norm(), limits.angular_acceleration * kDt + 1e-12);
    if (m.angular_velocity().norm() > 0) {
      EXPECT_NEAR(m.angular_velocity().normalized().z(), 1.0, 1e-9);
    }
    previous = m.angular_velocity();
    EXPECT_EQ(m.pose().position, start.position) << "a pure rotation does not move the tool point";
  }
  EXPECT_LT(rotation_error(goal.rotation, m.pose().rotation).norm(), 1e-12);
  EXPECT_NEAR(steps * kDt, 0.6 / limits.angular_speed + limits.angular_speed / limits.angular_acceleration, 0.01);
}

TEST(CartesianMotion, AGoalThatMovesOnTheWayIsFollowedSmoothly) {
  const Limits limits{0.25, 1.0, 1.0, 4.0};
  CartesianMotion m;
  m.reset(at(0, 0, 0));
  Vec3 previous = Vec3::Zero();
  for (int k = 0; k < 3000; ++k) {
    const Pose goal = k < 200 ? at(0.2, 0, 0) : at(0.1, 0.15, 0);  // turns at 0.2 s
    m.step(goal, limits, kDt);
    EXPECT_LE((m.velocity() - previous).norm(), limits.acceleration * kDt + 1e-12) << "step " << k;
    previous = m.velocity();
  }
  EXPECT_LT((m.pose().position - Vec3(0.1, 0.15, 0)).norm(), 1e-12);
}

TEST(CartesianMotion, APoseWithANaNIsNoPose) {
  std::array<double, 6> x{0, 0, 0, 0, 0, std::nan("")};
  EXPECT_FALSE(finite_pose(x));
  x[5] = 0;
  EXPECT_TRUE(finite_pose(x));
}

}  // namespace
}  // namespace chimera::modules::cartesian
