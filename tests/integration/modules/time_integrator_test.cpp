// time_integrator: its ports, the integral of a constant rate exact to rounding, the start at the
// measured posture, the bound on its lead over the arm, and its optional bounds.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "module_harness.hpp"
#include "support/port_contract.hpp"

namespace chimera::test {
namespace {

CHIMERA_REGISTER_MODULE(ScriptedSource);

constexpr const char* kFile = R"(subsystem: integ_test
constants: { ndof: [3] }
tasks:
  - { name: rates, module: scripted_source, period: 2ms, params: { port: dtheta_d, size: 3 } }
  - { name: joints, module: scripted_source, period: 2ms, params: { port: theta_m, size: 3 } }
  - { name: integ, module: time_integrator, period: 2ms, params: { max_lead: 0 } }
)";

TEST(TimeIntegrator, PortsFollowTheContract) {
  expect_ports("time_integrator", {{"ndof", PortKind::kInConst, "1"},
                                   {"dtheta_d", PortKind::kInVar, "ndof"},
                                   {"theta_m", PortKind::kInVar, "ndof"},
                                   {"theta_d", PortKind::kOutVar, "ndof"}});
}

TEST(TimeIntegrator, StartsAtTheArmAndIntegratesOverThePeriod) {
  ScriptedSource::set("joints", {0.5, -1.0, 2.0});
  ScriptedSource::set("rates", {0.25, -0.5, 1.0});
  auto sub = start_subsystem(kFile);
  ASSERT_NE(sub, nullptr);
  EXPECT_EQ(value_of(*sub, "theta_d"), (std::vector<double>{0.5, -1.0, 2.0}));  // on: where the arm is
  sub->run_for(1000 * kMs);  // 500 cycles of 2 ms: the release at 1 s is not run yet
  const auto theta_d = value_of(*sub, "theta_d");
  ASSERT_EQ(theta_d.size(), 3U);
  EXPECT_NEAR(theta_d[0], 0.5 + 0.25 * 1.0, 1e-12);
  EXPECT_NEAR(theta_d[1], -1.0 - 0.5 * 1.0, 1e-12);
  EXPECT_NEAR(theta_d[2], 2.0 + 1.0 * 1.0, 1e-12);
  // A change of rate applies from the next cycle on.
  ScriptedSource::set("rates", {0.0, 0.0, -4.0});
  sub->run_for(100 * kMs);
  EXPECT_NEAR(value_of(*sub, "theta_d")[2], 3.0 - 4.0 * 0.1, 1e-12);
  EXPECT_NEAR(value_of(*sub, "theta_d")[0], 0.75, 1e-12);
}

TEST(TimeIntegrator, NeverLeadsTheArmByMoreThanMaxLead) {
  // The arm does not move (it is held); the rate goes on: theta_d stops max_lead away.
  ScriptedSource::set("joints", {0.0, 0.0, 0.0});
  ScriptedSource::set("rates", {1.0, -2.0, 0.01});
  auto sub = start_subsystem(replaced(kFile, "max_lead: 0", "max_lead: 0.05"));
  ASSERT_NE(sub, nullptr);
  sub->run_for(1000 * kMs);
  const auto theta_d = value_of(*sub, "theta_d");
  EXPECT_DOUBLE_EQ(theta_d[0], 0.05);
  EXPECT_DOUBLE_EQ(theta_d[1], -0.05);
  EXPECT_NEAR(theta_d[2], 0.01, 1e-12);  // within the lead: integrated as usual
  // An arm that moved away drags theta_d along to within max_lead (0.25), from where it
  // integrates on: 4 more cycles of 2 ms at 1 rad/s in the next 10 ms.
  ScriptedSource::set("joints", {0.3, 0.0, 0.0});
  sub->run_for(10 * kMs);
  EXPECT_NEAR(value_of(*sub, "theta_d")[0], 0.25 + 4 * 0.002, 1e-12);
}

TEST(TimeIntegrator, KeepsWithinItsBounds) {
  ScriptedSource::set("joints", {0.0, 0.0, 0.0});
  ScriptedSource::set("rates", {1.0, -1.0, 1.0});
  auto sub = start_subsystem(replaced(kFile, "max_lead: 0", "max_lead: 0, lower: [-0.2], upper: [0.3, 0.3, 0.1]"));
  ASSERT_NE(sub, nullptr);
  sub->run_for(1000 * kMs);
  EXPECT_EQ(value_of(*sub, "theta_d"), (std::vector<double>{0.3, -0.2, 0.1}));
}

TEST(TimeIntegrator, MustBePeriodicAndWellBounded) {
  ScriptedSource::set("joints", {0.0, 0.0, 0.0});
  ScriptedSource::set("rates", {0.0, 0.0, 0.0});
  EXPECT_NE(start_error(replaced(kFile, "module: time_integrator, period: 2ms,", "module: time_integrator,"))
                .find("must be periodic"),
            std::string::npos);
  EXPECT_NE(start_error(replaced(kFile, "max_lead: 0", "max_lead: -1")).find("params.max_lead: -1 given: must be >= 0"),
            std::string::npos);
  EXPECT_NE(start_error(replaced(kFile, "max_lead: 0", "lower: [1], upper: [0]")).find("a lower bound is above"),
            std::string::npos);
}

}  // namespace
}  // namespace chimera::test
