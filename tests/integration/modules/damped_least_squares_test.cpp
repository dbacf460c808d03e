// damped_least_squares: its ports; the law against its mathematics (the exact inverse away from
// singularities, the damping of Nakamura and Hanafusa, joint speeds bounded by |v| / (2 lambda)
// at a singularity where the undamped inverse explodes); and in a running subsystem, the arm
// stretched toward a pose beyond its reach, through the singular posture, with bounded speeds.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "damped_least_squares/dls_law.hpp"
#include "kinematics_fixture.hpp"
#include "module_harness.hpp"
#include "support/port_contract.hpp"

namespace chimera::test {
namespace {

CHIMERA_REGISTER_MODULE(ScriptedSource);

using kinematics::JacobianMatrix;
using kinematics::Vector6;
using modules::DlsLaw;
using modules::DlsSettings;

JacobianMatrix jacobian_at(const std::vector<double>& q) {
  kinematics::Pose pose;
  JacobianMatrix j(6, 6);
  shipped_chain().evaluate(q, pose, j);
  return j;
}

double norm(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x * x;
  return std::sqrt(s);
}

// Unit twists in many directions, the same on every run.
std::vector<Vector6> twists() {
  std::vector<Vector6> out;
  std::uint64_t state = 7;
  for (int k = 0; k < 200; ++k) {
    Vector6 v;
    for (Eigen::Index i = 0; i < 6; ++i) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      v[i] = static_cast<double>(state >> 11U) / 9007199254740992.0 - 0.5;
    }
    out.push_back(v.normalized());
  }
  return out;
}

TEST(DampedLeastSquares, PortsFollowTheContract) {
  expect_ports("damped_least_squares", {{"ndof", PortKind::kInConst, "1"},
                                        {"x_d", PortKind::kInVar, "6"},
                                        {"x_m", PortKind::kInVar, "6"},
                                        {"jacobian", PortKind::kInVar, "6*ndof"},
                                        {"dtheta_d", PortKind::kOutVar, "ndof"}});
}

TEST(DampedLeastSquares, TheDampingGrowsAsTheManipulabilityFalls) {
  DlsLaw law;
  DlsSettings s;
  s.max_damping = 0.1;
  s.manipulability_threshold = 0.02;
  law.configure(s);
  EXPECT_DOUBLE_EQ(law.damping_squared(0.05), 0.0);
  EXPECT_DOUBLE_EQ(law.damping_squared(0.02), 0.0);
  EXPECT_DOUBLE_EQ(law.damping_squared(0.01), 0.01 * (1.0 - 0.25));
  EXPECT_DOUBLE_EQ(law.damping_squared(0.0), 0.01);
  double previous = -1.0;
  for (double w = 0.02; w >= 0.0; w -= 0.001) {
    EXPECT_GE(law.damping_squared(w), previous);
    previous = law.damping_squared(w);
  }
}

TEST(DampedLeastSquares, AwayFromSingularitiesItIsTheExactInverse) {
  DlsLaw law;
  law.configure(DlsSettings{});
  const JacobianMatrix j = jacobian_at({0.1, -0.2, 0.7, 0.3, 1.1, -0.4});
  std::vector<double> dtheta(6);
  for (const Vector6& v : twists()) {
    law.update(j, 0.2 * v, dtheta);
    const Eigen::Map<const Eigen::Matrix<double, 6, 1>> rates(dtheta.data());
    EXPECT_LT((j * rates - 0.2 * v).norm(), 1e-12);
  }
  EXPECT_GT(law.manipulability(), DlsSettings{}.manipulability_threshold);
  EXPECT_EQ(law.damping(), 0.0);
}

TEST(DampedLeastSquares, AtASingularityJointSpeedsStayBelowTwistOverTwiceLambda) {
  DlsLaw law;
  law.configure(DlsSettings{});  // max_damping 0.05
  // The elbow straight: the Jacobian loses the radial direction. Also nearly straight, where
  // the undamped inverse exists but asks for enormous joint speeds.
  for (const double elbow : {std::numbers::pi / 2, std::numbers::pi / 2 - 1e-4}) {
    const JacobianMatrix j = jacobian_at({0.2, 0.3, elbow, 0.1, 0.9, -0.2});
    std::vector<double> dtheta(6);
    double fastest = 0.0;
    double fastest_undamped = 0.0;
    for (const Vector6& v : twists()) {
      law.update(j, 0.3 * v, dtheta);
      fastest = std::max(fastest, norm(dtheta));
      EXPECT_LE(norm(dtheta), 0.3 / (2.0 * law.damping()) + 1e-9);
      const Eigen::Matrix<double, 6, 6> square = j;
      fastest_undamped = std::max(fastest_undamped, (square.inverse() * (0.3 * v)).norm());
    }
    EXPECT_LT(law.manipulability(), 1e-4);
    EXPECT_NEAR(law.damping(), 0.05, 1e-4);  // w far below w_0: nearly the full damping
    std::cout << "elbow " << elbow << ": fastest joint speed (|dtheta|) for a 0.3 m/s twist " << fastest
              << " rad/s damped, " << fastest_undamped << " rad/s undamped\n";
    EXPECT_LT(fastest, 3.0);  // <= 0.3 / (2 * 0.05)
    if (elbow < std::numbers::pi / 2) {
      EXPECT_GT(fastest_undamped, 100.0 * fastest);
    }
  }
}

TEST(DampedLeastSquares, TheCommandedTwistIsClipped) {
  DlsSettings s;
  s.gain = 10.0;
  s.max_linear_speed = 0.2;
  s.max_angular_speed = 0.5;
  DlsLaw law;
  law.configure(s);
  const auto far = kinematics::pose_from(std::vector<double>{1.0, 0.0, 1.0, 0.0, 0.0, 1.0});
  const auto here = kinematics::pose_from(std::vector<double>{0.0, 0.0, 1.0, 0.0, 0.0, 0.0});
  const Vector6 v = law.twist(far, here);
  EXPECT_NEAR(v.head<3>().norm(), 0.2, 1e-12);
  EXPECT_NEAR(v.tail<3>().norm(), 0.5, 1e-12);
  const auto near = kinematics::pose_from(std::vector<double>{0.01, 0.0, 1.0, 0.0, 0.0, 0.02});
  const Vector6 small = law.twist(near, here);
  EXPECT_NEAR(small[0], 0.1, 1e-12);  // gain * error below the limits
  EXPECT_NEAR(small[5], 0.2, 1e-12);
}

// The Figure 9 loop, driven toward a pose beyond the arm's reach: the arm stretches out into the
// singular posture of the straight elbow, and in every cycle where the damping acts the joint
// speed commanded stays below |v| / (2 lambda).
TEST(DampedLeastSquares, StretchesIntoTheSingularityWithBoundedJointSpeeds) {
  const char* text = R"(subsystem: dls_test
tasks:
  - { name: goal, module: scripted_source, period: 1ms, params: { port: x_d, size: 6 } }
  - { name: fk, module: fwd_kin_jacobian, period: 1ms }
  - { name: dls, module: damped_least_squares, period: 1ms, params: { gain: 5, max_linear_speed: 0.3 } }
  - { name: integ, module: time_integrator, period: 1ms }
  - { name: robot, module: robot_position, period: 1ms, params: { initial: [0.0, -0.2, 0.7, 0.0, 1.4, 0.0] } }
)";
  const std::vector<double> goal{1.2, 0.1, 0.76, 0.0, 2.356, 0.0};  // 27 cm beyond the reach
  ScriptedSource::set("goal", goal);
  auto sub = start_subsystem(text);
  ASSERT_NE(sub, nullptr);
  DlsSettings settings;
  settings.gain = 5.0;
  settings.max_linear_speed = 0.3;
  DlsLaw law;  // the module's law, to know the twist and the damping of each cycle
  law.configure(settings);
  double fastest = 0.0;
  double lowest_w = 1.0;
  int damped_cycles = 0;
  for (int k = 0; k < 3000; ++k) {
    sub->run_for(kMs);
    // What dls read this instant (fk runs before it) and what it wrote.
    const auto jacobian = value_of(*sub, "jacobian");
    const auto x_m = value_of(*sub, "x_m");
    const double speed = norm(value_of(*sub, "dtheta_d"));
    ASSERT_EQ(jacobian.size(), 36U);
    const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> j(jacobian.data());
    const double w = std::sqrt(std::max((j * j.transpose()).determinant(), 0.0));
    lowest_w = std::min(lowest_w, w);
    fastest = std::max(fastest, speed);
    const double lambda2 = law.damping_squared(w);
    if (lambda2 > 0.0) {
      ++damped_cycles;
      const double twist = law.twist(kinematics::pose_from(goal), kinematics::pose_from(x_m)).norm();
      ASSERT_LE(speed, twist / (2.0 * std::sqrt(lambda2)) + 1e-9) << "cycle " << k << ", w " << w;
    }
  }
  const auto theta_m = value_of(*sub, "theta_m");
  std::cout << "stretching toward an unreachable pose: elbow at " << theta_m[2] << " rad, lowest manipulability "
            << lowest_w << ", " << damped_cycles << " damped cycles, fastest command " << fastest << " rad/s\n";
  EXPECT_NEAR(theta_m[2], std::numbers::pi / 2, 0.05);  // stretched out, at the singular posture
  EXPECT_LT(lowest_w, 1e-3);
  EXPECT_GT(damped_cycles, 1000);
  // Everywhere, damped or not: at most the gain just above w_0 (about 20 rad/s per m/s on this
  // arm, 25 with margin) times the clipped twist.
  EXPECT_LT(fastest, 25.0 * 0.3);
  for (const auto& t : sub->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name << ": " << t.last_error;
}

TEST(DampedLeastSquares, ConvergesOnAReachablePose) {
  const char* text = R"(subsystem: dls_reach
tasks:
  - { name: goal, module: scripted_source, period: 1ms, params: { port: x_d, size: 6 } }
  - { name: fk, module: fwd_kin_jacobian, period: 1ms }
  - { name: dls, module: damped_least_squares, period: 1ms }
  - { name: integ, module: time_integrator, period: 1ms }
  - { name: robot, module: robot_position, period: 1ms, params: { initial: [0.0, -0.2, 0.7, 0.0, 1.4, 0.0] } }
)";
  const std::vector<double> goal{0.80, 0.25, 0.85, 0.3, 2.2, 0.1};
  ScriptedSource::set("goal", goal);
  auto sub = start_subsystem(text);
  ASSERT_NE(sub, nullptr);
  sub->run_for(3000 * kMs);
  const auto e = pose_difference(goal, value_of(*sub, "x_m"));
  EXPECT_LT(kinematics::position_norm(e), 1e-5);
  EXPECT_LT(kinematics::orientation_norm(e), 1e-5);
}

TEST(DampedLeastSquares, BadParametersDoNotStart) {
  const char* text = R"(subsystem: dls_bad
constants: { ndof: [6], x_d: [0, 0, 1, 0, 0, 0], x_m: [0, 0, 1, 0, 0, 0], jacobian: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0] }
tasks:
  - { name: dls, module: damped_least_squares, period: 1ms, params: { max_damping: 0 } }
)";
  EXPECT_NE(start_error(text).find("must be > 0"), std::string::npos) << start_error(text);
}

}  // namespace
}  // namespace chimera::test
