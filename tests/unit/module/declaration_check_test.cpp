// The checks the plugin loader applies to a library's modules (module/detail/declaration_check):
// each flaw gets its message, and every module shipped with chimera passes them.

#include "module/detail/declaration_check.hpp"

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "chimera/module/registry.hpp"

namespace chimera::module_detail {
namespace {

class Nothing final : public Module {};

ModuleInfo module(std::string name, std::function<void(Declarations&, const Params&)> declare) {
  return ModuleInfo{std::move(name), "test", "", std::move(declare),
                    []() -> std::unique_ptr<Module> { return std::make_unique<Nothing>(); }};
}

// The message check_module gives a module declared by `declare`, or "" when it passes.
std::string flaw(const std::function<void(Declarations&)>& declare) {
  auto r = check_module(module("m", [&](Declarations& d, const Params&) { declare(d); }));
  return r.ok() ? std::string() : r.error().message;
}

TEST(CheckModule, EveryShippedModulePasses) {
  const auto modules = Registry::global().list();
  ASSERT_FALSE(modules.empty());
  for (const ModuleInfo* m : modules) {
    const auto r = check_module(*m);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  }
}

TEST(CheckModule, AWellDeclaredModulePasses) {
  EXPECT_EQ(flaw([](Declarations& d) {
              d.in_const("ndof", Dim::fixed(1), "");
              d.in_var("theta_m", Dim::of("ndof"), "");
              d.out_var("jacobian", Dim::of("ndof", 6), "");
              d.out_var("log", Dim::follow(), "");
              d.out_const("count", {2}, "");
              d.param("gain", 1.0, "", "");
            }),
            "");
}

TEST(CheckModule, NamesMustBeIdentifiers) {
  auto r = check_module(module("my module", [](Declarations&, const Params&) {}));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "module 'my module': not a valid module name (letters, digits and _)");
  EXPECT_EQ(flaw([](Declarations& d) { d.in_var("2x", Dim::fixed(1), ""); }),
            "module m: port '2x' is not a valid name (letters, digits and _, not starting with a digit)");
  EXPECT_EQ(flaw([](Declarations& d) { d.param("", 1.0, "", ""); }),
            "module m: parameter '' is not a valid name (letters, digits and _, not starting with a digit)");
}

TEST(CheckModule, NothingDeclaredTwice) {
  EXPECT_EQ(flaw([](Declarations& d) {
              d.in_var("x", Dim::fixed(1), "");
              d.out_var("x", Dim::fixed(1), "");
            }),
            "module m: port x is declared twice");
  EXPECT_EQ(flaw([](Declarations& d) {
              d.param("k", 1.0, "", "");
              d.param("k", true, "", "");
            }),
            "module m: parameter k is declared twice");
}

TEST(CheckModule, SizesAreAtLeastOneAndNameAConstPort) {
  EXPECT_EQ(flaw([](Declarations& d) { d.out_var("x", Dim::fixed(0), ""); }), "module m: port x has size 0");
  EXPECT_EQ(flaw([](Declarations& d) {
              d.out_var("x", Dim{1, "ndof", true}, "");
            }),
            "module m: port x both follows its variable's size and is sized by ndof");
  EXPECT_EQ(flaw([](Declarations& d) {
              d.in_var("ndof", Dim::fixed(1), "");
              d.out_var("x", Dim::of("ndof"), "");
            }),
            "module m: port x is sized by ndof, which is not one of the module's f64 const ports (declare "
            "in_const(\"ndof\", ...) or out_const)");
  EXPECT_EQ(flaw([](Declarations& d) { d.out_const("ndof", {}, ""); }),
            "module m: out-const ndof has no value (declare it with at least one number)");
}

TEST(CheckModule, ADeclareThatThrowsIsAFlaw) {
  auto r = check_module(module("m", [](Declarations&, const Params&) { throw std::runtime_error("boom"); }));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "module m: declare() threw: boom");
}

TEST(CheckModule, ParameterRulesThatCannotHoldAreRefused) {
  EXPECT_EQ(flaw([](Declarations& d) { d.param("gain", 1.0, "", "").at_least(2); }),
            "module m: parameter gain: its default 1 breaks its own rule: must be >= 2");
  EXPECT_EQ(flaw([](Declarations& d) { d.param("gain", 1.0, "", "").greater_than(3).less_than(2); }),
            "module m: parameter gain: its range > 3 and < 2 holds no value");
  EXPECT_EQ(flaw([](Declarations& d) { d.param("gain", 1.0, "", "").at_least(1).less_than(1); }),
            "module m: parameter gain: its range >= 1 and < 1 holds no value");
  EXPECT_EQ(flaw([](Declarations& d) { d.param("name", std::string("x"), "", "").at_least(0); }),
            "module m: parameter name is string, which cannot have a range");
  EXPECT_EQ(flaw([](Declarations& d) { d.param("on", true, "", "").one_of({"yes"}); }),
            "module m: parameter on is bool, which cannot have choices");
  EXPECT_EQ(flaw([](Declarations& d) { d.refuse("a rule for parameter 'k', which is not declared before it"); }),
            "module m: a rule for parameter 'k', which is not declared before it");
  EXPECT_EQ(flaw([](Declarations& d) { d.param("gain", 1.0, "", "").at_least(1).at_most(1); }), "");
}

}  // namespace
}  // namespace chimera::module_detail
