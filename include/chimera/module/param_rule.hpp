#pragma once
// What values a module's parameter accepts beyond its type: a range for numbers (every element of
// a vector or matrix) and a list of choices for text (every item of a string list). Declared with
// the parameter, checked by the loader, so that `chimera verify` refuses with file and line what
// the module's init would refuse later, and shown by `chimera modules` and the module docs.
//
//   d.param("cutoff_hz", 10.0, "Hz", "corner frequency").greater_than(0);
//   d.param("noise_std", 0.0, "rad", "measurement noise").at_least(0);
//   d.param("size", 6.0, "", "numbers per datagram").whole().at_least(1).at_most(256);
//   d.param("mode", std::string("torque"), "", "command mode").one_of({"torque", "position"});

#include <optional>
#include <string>
#include <vector>

#include "chimera/module/params.hpp"

namespace chimera {

struct ParamRule {
  std::optional<double> lower{};  // a bound below, inclusive unless lower_exclusive
  bool lower_exclusive = false;
  std::optional<double> upper{};  // a bound above, inclusive unless upper_exclusive
  bool upper_exclusive = false;
  bool whole = false;                  // numbers only: whole numbers (counts, sizes, ports)
  std::vector<std::string> choices{};  // empty: any text

  [[nodiscard]] bool empty() const { return !lower && !upper && !whole && choices.empty(); }
};

/// The rule in words, for messages and docs: "> 0", "whole, >= 1 and <= 64", "one of: torque,
/// position"; "" for no rule.
[[nodiscard]] std::string describe(const ParamRule& rule);

/// "" when `value` keeps the rule; else why not, one line naming the offending element:
/// "must be > 0", "element 3 is -1, must be >= 0", "must be one of: torque, position".
[[nodiscard]] std::string rule_violation(const ParamRule& rule, const ParamValue& value);

/// What Declarations::param() returns: the rule of the parameter just declared, to chain on.
/// Use it in the same statement; it refers into the declarations.
class ParamRuleBuilder {
 public:
  explicit ParamRuleBuilder(ParamRule& rule) : rule_(rule) {}
  ParamRuleBuilder& at_least(double v) {
    rule_.lower = v;
    rule_.lower_exclusive = false;
    return *this;
  }
  ParamRuleBuilder& greater_than(double v) {
    rule_.lower = v;
    rule_.lower_exclusive = true;
    return *this;
  }
  ParamRuleBuilder& at_most(double v) {
    rule_.upper = v;
    rule_.upper_exclusive = false;
    return *this;
  }
  ParamRuleBuilder& less_than(double v) {
    rule_.upper = v;
    rule_.upper_exclusive = true;
    return *this;
  }
  ParamRuleBuilder& whole() {
    rule_.whole = true;
    return *this;
  }
  ParamRuleBuilder& one_of(std::vector<std::string> choices) {
    rule_.choices = std::move(choices);
    return *this;
  }

 private:
  ParamRule& rule_;
};

}  // namespace chimera
