// join_weighted_average: its ports (any number of inputs, each the size its variable has
// elsewhere in the file), the weighted mean, equal weights by default, and what it refuses.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "module_harness.hpp"
#include "support/port_contract.hpp"

namespace chimera::test {
namespace {

CHIMERA_REGISTER_MODULE(ScriptedSource);

// tracking_monitor reads the joined reading as theta_d, which gives the join's output its size.
constexpr const char* kFile = R"(subsystem: join_test
constants: { ndof: [3], theta_m: [0, 0, 0] }
tasks:
  - { name: a, module: scripted_source, period: 10ms, params: { port: reading_a, size: 3 } }
  - { name: b, module: scripted_source, period: 10ms, params: { port: reading_b, size: 3 } }
  - { name: c, module: scripted_source, period: 10ms, params: { port: reading_c, size: 3 } }
  - name: join
    module: join_weighted_average
    period: 10ms
    params: { weights: [1, 2, 5] }
    rename: { in_0: reading_a, in_1: reading_b, in_2: reading_c, out: theta_d }
  - { name: reader, module: tracking_monitor, period: 10ms }
)";

TEST(JoinWeightedAverage, PortsFollowTheirVariablesAndTheNumberOfInputs) {
  expect_ports(
      "join_weighted_average",
      {{"in_0", PortKind::kInVar, "any"}, {"in_1", PortKind::kInVar, "any"}, {"out", PortKind::kOutVar, "any"}});
  Params three;
  three.set("inputs", 3.0);
  expect_ports("join_weighted_average",
               {{"in_0", PortKind::kInVar, "any"},
                {"in_1", PortKind::kInVar, "any"},
                {"in_2", PortKind::kInVar, "any"},
                {"out", PortKind::kOutVar, "any"}},
               three);
  Params four_weights;
  four_weights.set("weights", Vector{1, 1, 1, 1});
  EXPECT_EQ(Registry::global().find("join_weighted_average")->declarations(four_weights).ports().size(), 5U);
}

TEST(JoinWeightedAverage, PublishesTheWeightedMean) {
  ScriptedSource::set("a", {1.0, 10.0, -3.0});
  ScriptedSource::set("b", {2.0, 20.0, 0.0});
  ScriptedSource::set("c", {4.0, 0.0, 3.0});
  auto sub = start_subsystem(kFile);
  ASSERT_NE(sub, nullptr);
  sub->run_for(20 * kMs);
  const auto out = value_of(*sub, "theta_d");
  ASSERT_EQ(out.size(), 3U);  // the size of the readings it joins
  EXPECT_DOUBLE_EQ(out[0], (1 * 1.0 + 2 * 2.0 + 5 * 4.0) / 8.0);
  EXPECT_DOUBLE_EQ(out[1], (1 * 10.0 + 2 * 20.0 + 5 * 0.0) / 8.0);
  EXPECT_DOUBLE_EQ(out[2], (1 * -3.0 + 2 * 0.0 + 5 * 3.0) / 8.0);
  // Each cycle joins the values of that instant (the producers run first at a shared release).
  ScriptedSource::set("c", {0.0, 0.0, 0.0});
  sub->run_for(10 * kMs);
  EXPECT_DOUBLE_EQ(value_of(*sub, "theta_d")[0], (1 * 1.0 + 2 * 2.0) / 8.0);
}

TEST(JoinWeightedAverage, EqualWeightsByDefault) {
  ScriptedSource::set("a", {1.0, 2.0, 3.0});
  ScriptedSource::set("b", {3.0, 2.0, 1.0});
  ScriptedSource::set("c", {2.0, 5.0, 8.0});
  auto sub = start_subsystem(replaced(kFile, "params: { weights: [1, 2, 5] }", "params: { inputs: 3 }"));
  ASSERT_NE(sub, nullptr);
  sub->run_for(10 * kMs);
  EXPECT_EQ(value_of(*sub, "theta_d"), (std::vector<double>{2.0, 3.0, 4.0}));
}

TEST(JoinWeightedAverage, RefusesBadWeightsAndMixedShapes) {
  ScriptedSource::set("a", {0.0, 0.0, 0.0});
  ScriptedSource::set("b", {0.0, 0.0, 0.0});
  ScriptedSource::set("c", {0.0, 0.0, 0.0});
  EXPECT_NE(
      start_error(replaced(kFile, "weights: [1, 2, 5]", "inputs: 3, weights: [1, 2]")).find("2 weights for 3 inputs"),
      std::string::npos);
  EXPECT_NE(start_error(replaced(kFile, "weights: [1, 2, 5]", "weights: [1, -2, 5]")).find("params.weights: [1, -2, 5] given: element 1 is -2, must be >= 0"),
            std::string::npos);
  EXPECT_NE(start_error(replaced(kFile, "weights: [1, 2, 5]", "weights: [0, 0, 0]")).find("must not all be 0"),
            std::string::npos);
  const std::string mixed = replaced(kFile, "port: reading_b, size: 3", "port: reading_b, size: 6");
  EXPECT_NE(start_error(mixed).find("in_1 has 6 elements but out has 3"), std::string::npos) << start_error(mixed);
}

}  // namespace
}  // namespace chimera::test
