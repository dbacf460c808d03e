// The three modules of Figure 4 one by one: their declared ports against the contract (section 3),
// and the trajectory and PID laws.

#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"
#include "joint_traj_gen/quintic_via.hpp"
#include "pid_joint/pid_law.hpp"
#include "support/port_contract.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kS = 1'000'000'000;

// ---- ports: the names, kinds and sizes the contract gives --------------------------------------

using test::expect_ports;

TEST(Fig4Modules, PortsFollowTheContract) {
  expect_ports("joint_traj_gen", {{"ndof", PortKind::kInConst, "1"},
                                  {"theta_m", PortKind::kInVar, "ndof"},
                                  {"theta_d", PortKind::kOutVar, "ndof"},
                                  {"dtheta_d", PortKind::kOutVar, "ndof"}});
  expect_ports("pid_joint", {{"ndof", PortKind::kInConst, "1"},
                             {"theta_d", PortKind::kInVar, "ndof"},
                             {"dtheta_d", PortKind::kInVar, "ndof"},
                             {"theta_m", PortKind::kInVar, "ndof"},
                             {"dtheta_m", PortKind::kInVar, "ndof"},
                             {"tau_r", PortKind::kOutVar, "ndof"}});
  // The robot's sizes come from its own ndof parameter (6 by default).
  expect_ports("robot_torque", {{"tau_r", PortKind::kInVar, "6"},
                                {"theta_m", PortKind::kOutVar, "6"},
                                {"dtheta_m", PortKind::kOutVar, "6"},
                                {"ndof", PortKind::kOutConst, "1"}});
  const Declarations robot = Registry::global().find("robot_torque")->declarations(Params{});
  EXPECT_FALSE(robot.resource().empty());
  for (const auto& p : robot.ports()) {
    if (p.name == "ndof") {
      EXPECT_EQ(p.value, std::vector<double>{6.0});
    }
  }
}

// ---- joint_traj_gen's law ----------------------------------------------------------------------

constexpr std::size_t kN = 2;

modules::QuinticVia make_path(bool loop) {
  modules::QuinticVia path;
  path.configure(kN, {1.0, -2.0, 3.0, 0.0}, 2 * kS, kS / 2, loop);  // vias (1,-2) and (3,0)
  const std::vector<double> start{0.0, 0.0};
  path.restart(start);
  return path;
}

std::vector<double> pos_at(const modules::QuinticVia& p, std::int64_t t, std::vector<double>* vel = nullptr) {
  std::vector<double> q(kN);
  std::vector<double> v(kN);
  p.sample(t, q, v);
  if (vel) *vel = v;
  return q;
}

TEST(Fig4Modules, QuinticStartsAndEndsAtRest) {
  const auto path = make_path(true);
  std::vector<double> v;
  EXPECT_EQ(pos_at(path, 0, &v), (std::vector<double>{0.0, 0.0}));
  EXPECT_EQ(v, (std::vector<double>{0.0, 0.0}));
  EXPECT_EQ(pos_at(path, 2 * kS, &v), (std::vector<double>{1.0, -2.0}));  // at the via point...
  EXPECT_EQ(v, (std::vector<double>{0.0, 0.0}));
  EXPECT_EQ(pos_at(path, 2 * kS + kS / 4), (std::vector<double>{1.0, -2.0}));  // ...and resting there
  // Halfway: half the distance, at the quintic's peak speed 15/8 * distance / duration.
  const auto mid = pos_at(path, kS, &v);
  EXPECT_DOUBLE_EQ(mid[0], 0.5);
  EXPECT_DOUBLE_EQ(v[0], 15.0 / 8.0 * 1.0 / 2.0);
  EXPECT_DOUBLE_EQ(v[1], 15.0 / 8.0 * -2.0 / 2.0);
  // Near the ends the speed vanishes like t^2 (zero acceleration too).
  pos_at(path, kMs, &v);
  EXPECT_LT(std::fabs(v[0]), 1e-5);
}

TEST(Fig4Modules, QuinticVelocityIsTheDerivativeOfPosition) {
  const auto path = make_path(true);
  for (std::int64_t t = 0; t < 12 * kS; t += 37 * kMs) {
    std::vector<double> v;
    const auto q0 = pos_at(path, t, &v);
    const auto q1 = pos_at(path, t + kMs);
    for (std::size_t j = 0; j < kN; ++j) EXPECT_NEAR((q1[j] - q0[j]) / 1e-3, v[j], 0.01) << "t " << t << " j " << j;
  }
}

TEST(Fig4Modules, QuinticLoopsThroughTheViaPointsOrHoldsTheLast) {
  const auto looping = make_path(true);
  const auto once = make_path(false);
  const std::int64_t leg = 2 * kS + kS / 2;
  // Second leg ends at via 2, third leg goes back to via 1, and so on forever.
  EXPECT_EQ(pos_at(looping, 2 * leg - kS / 4), (std::vector<double>{3.0, 0.0}));
  EXPECT_EQ(pos_at(looping, 3 * leg - kS / 4), (std::vector<double>{1.0, -2.0}));
  EXPECT_EQ(pos_at(looping, 1001 * leg - kS / 4), (std::vector<double>{1.0, -2.0}));
  EXPECT_EQ(pos_at(once, 3 * leg - kS / 4), (std::vector<double>{3.0, 0.0}));
  EXPECT_EQ(pos_at(once, 1000 * leg), (std::vector<double>{3.0, 0.0}));
}

// ---- pid_joint's law ---------------------------------------------------------------------------

modules::PidLaw make_pid(double kp, double ki, double kd, double tau_max, double i_max) {
  modules::PidLaw pid;
  pid.configure({{kp}, {ki}, {kd}, {tau_max}, {i_max}}, 0.001);
  return pid;
}

double pid_out(modules::PidLaw& pid, double qd, double dqd, double qm, double dqm) {
  const std::array<double, 4> in{qd, dqd, qm, dqm};
  const std::span<const double> all(in);
  double tau = 0.0;
  pid.update(all.subspan(0, 1), all.subspan(1, 1), all.subspan(2, 1), all.subspan(3, 1), {&tau, 1});
  return tau;
}

TEST(Fig4Modules, PidIsProportionalIntegralAndDerivative) {
  auto pid = make_pid(100.0, 50.0, 10.0, 1e6, 1e6);
  // First sample: e = 0.2 integrated once over 1 ms.
  EXPECT_DOUBLE_EQ(pid_out(pid, 0.2, 1.0, 0.0, 0.5), 100.0 * 0.2 + 50.0 * 0.2 * 0.001 + 10.0 * 0.5);
  EXPECT_DOUBLE_EQ(pid.integral()[0], 0.2 * 0.001);
  pid.reset();
  EXPECT_EQ(pid.integral()[0], 0.0);
}

TEST(Fig4Modules, PidSaturatesAndDoesNotWindUp) {
  auto pid = make_pid(100.0, 1000.0, 0.0, 20.0, 1e6);
  // A large error saturates the output; the integral must not grow meanwhile.
  for (int k = 0; k < 1000; ++k) EXPECT_DOUBLE_EQ(pid_out(pid, 1.0, 0.0, 0.0, 0.0), 20.0);
  EXPECT_EQ(pid.integral()[0], 0.0);
  // So once the error reverses the output follows at once, with no stored windup to unwind.
  EXPECT_LT(pid_out(pid, 0.0, 0.0, 0.1, 0.0), -9.0);
  EXPECT_DOUBLE_EQ(pid_out(pid, -1.0, 0.0, 0.0, 0.0), -20.0);
}

TEST(Fig4Modules, PidIntegralIsBounded) {
  auto pid = make_pid(0.0, 1.0, 0.0, 1e6, 0.01);
  for (int k = 0; k < 100'000; ++k) (void)pid_out(pid, 1.0, 0.0, 0.0, 0.0);
  EXPECT_DOUBLE_EQ(pid.integral()[0], 0.01);
  EXPECT_DOUBLE_EQ(pid_out(pid, 1.0, 0.0, 0.0, 0.0), 0.01);
}

// The closed loop's freedom from allocation is proven in tests/rt/no_allocation_in_cycle_test.cpp.

}  // namespace
}  // namespace chimera
