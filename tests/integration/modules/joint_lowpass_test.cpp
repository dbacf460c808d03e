// joint_lowpass and torque_limit, the two modules Figure 4's filtered chain adds to its loop: their
// ports, the filter's exact step response and its start at the first input, the limiter's clamp.

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "module_harness.hpp"
#include "support/port_contract.hpp"

namespace chimera::test {
namespace {

CHIMERA_REGISTER_MODULE(ScriptedSource);

constexpr const char* kFilterFile = R"(subsystem: lowpass_test
constants: { ndof: [2] }
tasks:
  - { name: src, module: scripted_source, period: 1ms, params: { port: u, size: 2 } }
  - { name: filter, module: joint_lowpass, period: 1ms, params: { cutoff_hz: 20 } }
)";

constexpr const char* kLimitFile = R"(subsystem: limit_test
constants: { ndof: [3] }
tasks:
  - { name: src, module: scripted_source, period: 1ms, params: { port: tau_in, size: 3 } }
  - { name: limit, module: torque_limit, period: 1ms, params: { limit: [1, 2, 0.5] } }
)";

TEST(JointLowpass, PortsFollowTheContract) {
  expect_ports("joint_lowpass", {{"ndof", PortKind::kInConst, "1"}, {"u", PortKind::kInVar, "ndof"},
                                 {"y", PortKind::kOutVar, "ndof"}});
}

TEST(JointLowpass, StartsAtItsFirstInputAndFollowsAStepExactly) {
  ScriptedSource::set("src", {1.0, -2.0});
  auto sub = start_subsystem(kFilterFile);
  ASSERT_NE(sub, nullptr);
  sub->run_for(10 * kMs);
  EXPECT_EQ(value_of(*sub, "y"), (std::vector<double>{1.0, -2.0})) << "no ramp up from zero";
  // A step from (1, -2) to (3, 0): after n cycles y = u - (u - y0) (1 - alpha)^n.
  ScriptedSource::set("src", {3.0, 0.0});
  sub->run_for(20 * kMs);
  const double keep = std::exp(-2.0 * std::numbers::pi * 20.0 * 0.001);  // 1 - alpha
  const double n = 20;
  const auto y = value_of(*sub, "y");
  ASSERT_EQ(y.size(), 2U);
  EXPECT_NEAR(y[0], 3.0 - 2.0 * std::pow(keep, n), 1e-12);
  EXPECT_NEAR(y[1], 0.0 - (0.0 - -2.0) * std::pow(keep, n), 1e-12);
}

TEST(JointLowpass, RefusesACutoffThatIsNotPositive) {
  EXPECT_NE(start_error(replaced(kFilterFile, "cutoff_hz: 20", "cutoff_hz: 0")).find("params.cutoff_hz: 0 given: must be > 0"),
            std::string::npos);
}

TEST(TorqueLimit, PortsFollowTheContract) {
  expect_ports("torque_limit", {{"ndof", PortKind::kInConst, "1"}, {"tau_in", PortKind::kInVar, "ndof"},
                                {"tau_out", PortKind::kOutVar, "ndof"}});
}

TEST(TorqueLimit, ClampsEachJointToItsLimit) {
  ScriptedSource::set("src", {5.0, -1.5, -0.7});
  auto sub = start_subsystem(kLimitFile);
  ASSERT_NE(sub, nullptr);
  sub->run_for(5 * kMs);
  EXPECT_EQ(value_of(*sub, "tau_out"), (std::vector<double>{1.0, -1.5, -0.5}));
}

TEST(TorqueLimit, RefusesANegativeLimit) {
  EXPECT_NE(start_error(replaced(kLimitFile, "limit: [1, 2, 0.5]", "limit: [1, -2, 0.5]")).find("params.limit: [1, -2, 0.5] given: element 1 is -2, must be >= 0"),
            std::string::npos);
}

}  // namespace
}  // namespace chimera::test
