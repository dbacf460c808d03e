#include "chimera/module/param_rule.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace chimera {
namespace {

// 1000000 rather than 1e+06: bounds are read by people, in messages and docs.
std::string number_text(double x) {
  if (x == std::floor(x) && std::fabs(x) < 1e15) return fmt::format("{:.0f}", x);
  return fmt::format("{}", x);
}

std::string bound_text(const ParamRule& rule) {
  std::string out = rule.whole ? "whole" : "";
  if (rule.lower && !out.empty()) out += ",";
  if (rule.lower)
    out += fmt::format("{}{} {}", out.empty() ? "" : " ", rule.lower_exclusive ? ">" : ">=", number_text(*rule.lower));
  if (rule.upper)
    out += fmt::format("{}{} {}", rule.lower ? " and " : (out.empty() ? "" : ", "),
                       rule.upper_exclusive ? "<" : "<=", number_text(*rule.upper));
  return out;
}

bool in_range(const ParamRule& rule, double x) {
  if (std::isnan(x)) return !rule.lower && !rule.upper && !rule.whole;
  if (rule.whole && (!std::isfinite(x) || x != std::floor(x))) return false;
  if (rule.lower && (rule.lower_exclusive ? !(x > *rule.lower) : !(x >= *rule.lower))) return false;
  if (rule.upper && (rule.upper_exclusive ? !(x < *rule.upper) : !(x <= *rule.upper))) return false;
  return true;
}

bool chosen(const ParamRule& rule, const std::string& text) {
  return rule.choices.empty() || std::ranges::any_of(rule.choices, [&](const std::string& c) { return c == text; });
}

std::string choices_text(const ParamRule& rule) { return fmt::format("one of: {}", fmt::join(rule.choices, ", ")); }

}  // namespace

std::string describe(const ParamRule& rule) {
  std::string out = bound_text(rule);
  if (!rule.choices.empty()) out += (out.empty() ? "" : "; ") + choices_text(rule);
  return out;
}

std::string rule_violation(const ParamRule& rule, const ParamValue& value) {
  const auto number = [&](double x, const std::string& where) -> std::string {
    if (in_range(rule, x)) return {};
    return where.empty() ? fmt::format("must be {}", bound_text(rule))
                         : fmt::format("{} is {}, must be {}", where, number_text(x), bound_text(rule));
  };
  switch (param_type_of(value)) {
    case ParamType::kNumber: return number(std::get<double>(value), "");
    case ParamType::kVector: {
      const auto& v = std::get<Vector>(value);
      for (std::size_t i = 0; i < v.size(); ++i)
        if (auto why = number(v[i], fmt::format("element {}", i)); !why.empty()) return why;
      return {};
    }
    case ParamType::kMatrix: {
      const auto& m = std::get<Matrix>(value);
      for (std::size_t r = 0; r < m.size(); ++r)
        for (std::size_t c = 0; c < m[r].size(); ++c)
          if (auto why = number(m[r][c], fmt::format("element [{}][{}]", r, c)); !why.empty()) return why;
      return {};
    }
    case ParamType::kString:
      return chosen(rule, std::get<std::string>(value)) ? std::string() : "must be " + choices_text(rule);
    case ParamType::kStringList: {
      const auto& list = std::get<StringList>(value);
      for (std::size_t i = 0; i < list.size(); ++i)
        if (!chosen(rule, list[i])) return fmt::format("item {} is \"{}\", must be {}", i, list[i], choices_text(rule));
      return {};
    }
    case ParamType::kBool: return {};
  }
  return {};
}

}  // namespace chimera
