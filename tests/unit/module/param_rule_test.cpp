// A parameter's declared range and choices (module/param_rule.hpp): what each rule accepts, how it
// reads, and the declaration mistakes the plugin loader refuses.

#include "chimera/module/param_rule.hpp"

#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "chimera/module/declarations.hpp"

namespace chimera {
namespace {

ParamRule rule(const std::function<void(ParamRuleBuilder&)>& build) {
  ParamRule r;
  ParamRuleBuilder b(r);
  build(b);
  return r;
}

TEST(ParamRule, BoundsAreInclusiveOrExclusiveAsDeclared) {
  const auto positive = rule([](auto& b) { b.greater_than(0); });
  EXPECT_EQ(rule_violation(positive, 0.5), "");
  EXPECT_EQ(rule_violation(positive, 0.0), "must be > 0");
  const auto unit = rule([](auto& b) { b.at_least(0).at_most(1); });
  EXPECT_EQ(rule_violation(unit, 0.0), "");
  EXPECT_EQ(rule_violation(unit, 1.0), "");
  EXPECT_EQ(rule_violation(unit, 1.5), "must be >= 0 and <= 1");
  const auto below = rule([](auto& b) { b.less_than(1e6); });
  EXPECT_EQ(describe(below), "< 1000000");
  EXPECT_EQ(rule_violation(below, 1e6), "must be < 1000000");
}

TEST(ParamRule, NotANumberKeepsNoBoundAndWholeRefusesFractions) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(rule_violation(rule([](auto& b) { b.at_least(0); }), nan), "");
  const auto count = rule([](auto& b) { b.whole().at_least(1).at_most(64); });
  EXPECT_EQ(describe(count), "whole, >= 1 and <= 64");
  EXPECT_EQ(rule_violation(count, 6.0), "");
  EXPECT_EQ(rule_violation(count, 6.5), "must be whole, >= 1 and <= 64");
  EXPECT_EQ(rule_violation(count, std::numeric_limits<double>::infinity()), "must be whole, >= 1 and <= 64");
  EXPECT_EQ(describe(rule([](auto& b) { b.whole(); })), "whole");
  EXPECT_EQ(describe(rule([](auto& b) { b.whole().at_most(3); })), "whole, <= 3");
}

TEST(ParamRule, EveryElementOfAVectorOrMatrixIsChecked) {
  const auto gains = rule([](auto& b) { b.at_least(0); });
  EXPECT_EQ(rule_violation(gains, Vector{1, 2, 3}), "");
  EXPECT_EQ(rule_violation(gains, Vector{1, -2, 3}), "element 1 is -2, must be >= 0");
  EXPECT_EQ(rule_violation(gains, Matrix{{1, 2}, {3, -0.5}}), "element [1][1] is -0.5, must be >= 0");
  EXPECT_EQ(rule_violation(gains, Vector{}), "") << "an empty list breaks no bound";
}

TEST(ParamRule, ChoicesForTextAndEachItemOfAList) {
  const auto mode = rule([](auto& b) { b.one_of({"udp", "replay"}); });
  EXPECT_EQ(describe(mode), "one of: udp, replay");
  EXPECT_EQ(rule_violation(mode, std::string("replay")), "");
  EXPECT_EQ(rule_violation(mode, std::string("tcp")), "must be one of: udp, replay");
  EXPECT_EQ(rule_violation(mode, StringList{"udp", "x"}), "item 1 is \"x\", must be one of: udp, replay");
  EXPECT_EQ(describe(ParamRule{}), "");
  EXPECT_TRUE(ParamRule{}.empty());
}

TEST(ParamRule, DeclaredInTheSameStatementAsTheParameter) {
  Declarations d;
  d.param("cutoff_hz", 10.0, "Hz", "corner frequency").greater_than(0);
  d.param("mode", std::string("a"), "", "").one_of({"a", "b"});
  ASSERT_EQ(d.params().size(), 2u);
  EXPECT_EQ(describe(d.params()[0].rule), "> 0");
  EXPECT_EQ(describe(d.params()[1].rule), "one of: a, b");
  ASSERT_NE(d.rule_of("mode"), nullptr);
  EXPECT_EQ(d.rule_of("nothing"), nullptr);
}

}  // namespace
}  // namespace chimera
