#pragma once
// Checks a module's declared ports against contract section 3: names, kinds, f64, sizes.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/module/registry.hpp"

namespace chimera::test {

struct ExpectedPort {
  std::string name;
  PortKind kind;
  std::string dim;  // as to_string(Dim) prints it: "6", "ndof", "6*ndof", "any"
};

/// The module's ports with default parameters are exactly `expected`.
inline void expect_ports(const char* module, const std::vector<ExpectedPort>& expected,
                         const Params& params = Params{}) {
  const ModuleInfo* info = Registry::global().find(module);
  ASSERT_NE(info, nullptr) << module << " is not registered";
  EXPECT_FALSE(info->summary.empty());
  EXPECT_GT(info->doc.size(), 300U) << module << ": its documentation should be a real page";
  const Declarations d = info->declarations(params);
  ASSERT_EQ(d.ports().size(), expected.size()) << module;
  for (const auto& e : expected) {
    bool found = false;
    for (const auto& p : d.ports()) {
      if (p.name != e.name) continue;
      found = true;
      EXPECT_EQ(p.kind, e.kind) << module << "." << e.name;
      EXPECT_EQ(p.type, ElemType::kF64) << module << "." << e.name;
      EXPECT_EQ(to_string(p.dim), e.dim) << module << "." << e.name;
    }
    EXPECT_TRUE(found) << module << " lacks port " << e.name;
  }
}

}  // namespace chimera::test
