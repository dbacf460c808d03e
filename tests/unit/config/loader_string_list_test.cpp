// Parameters that are lists of text (ParamType::kStringList), such as the data logger's
// variables: how they are written, their defaults, and the messages for a wrong type.

#include <memory>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/module/registry.hpp"

namespace chimera {
namespace {

class Nothing final : public Module {};

const Registry& registry() {
  static const Registry r = [] {
    Registry reg;
    (void)reg.add(ModuleInfo{"recorder", "records", "",
                             [](Declarations& d, const Params&) {
                               d.param("variables", StringList{"theta_m"}, "", "what to record");
                               d.param("gains", Vector{}, "", "numbers");
                             },
                             []() -> std::unique_ptr<Module> { return std::make_unique<Nothing>(); }});
    return reg;
  }();
  return r;
}

Result<SubsystemSpec> load(std::string_view params) {
  return load_subsystem_text(
      "subsystem: s\ntasks:\n  - name: log\n    module: recorder\n    params: " + std::string(params) + "\n",
      "log.yaml", registry());
}

std::string error_of(std::string_view params) {
  auto r = load(params);
  EXPECT_FALSE(r.ok()) << params;
  return r.ok() ? std::string() : r.error().message;
}

TEST(StringListParams, ListsOfTextAreRead) {
  auto s = load("{ variables: [theta_d, \"theta_m\", x-d, \"3\"] }");
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->tasks[0].params.strings("variables"), (StringList{"theta_d", "theta_m", "x-d", "3"}));
}

TEST(StringListParams, TheDefaultAndTheEmptyList) {
  auto defaulted = load("{}");
  ASSERT_TRUE(defaulted.ok()) << defaulted.error().message;
  EXPECT_EQ(defaulted->tasks[0].params.strings("variables"), (StringList{"theta_m"}));
  auto empty = load("{ variables: [] }");
  ASSERT_TRUE(empty.ok()) << empty.error().message;
  const ParamValue* v = empty->tasks[0].params.find("variables");
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(param_type_of(*v), ParamType::kStringList) << "[] fits a list of strings too";
  EXPECT_TRUE(std::get<StringList>(*v).empty());
}

TEST(StringListParams, WrongTypesAreNamed) {
  EXPECT_EQ(error_of("{ variables: theta_m }"),
            "log.yaml:5: tasks[0].params.variables: \"theta_m\" is a string, but variables of recorder takes a list "
            "of strings");
  EXPECT_EQ(error_of("{ variables: [1, 2] }"),
            "log.yaml:5: tasks[0].params.variables: [1, 2] is a list of numbers, but variables of recorder takes a "
            "list of strings");
  EXPECT_EQ(error_of("{ gains: [a, b] }"),
            "log.yaml:5: tasks[0].params.gains: [\"a\", \"b\"] is a list of strings, but gains of recorder takes a "
            "list of numbers");
  EXPECT_EQ(error_of("{ variables: [theta_d, 3] }"),
            "log.yaml:5: tasks[0].params.variables[1]: \"3\" is a number, but the list holds text (quote it to make "
            "it text)");
  EXPECT_EQ(error_of("{ variables: [theta_d, [1]] }"),
            "log.yaml:5: tasks[0].params.variables[1]: a list is not text, but the list holds text (a list of "
            "strings)");
}

TEST(StringListParams, ShowsAsAList) {
  EXPECT_EQ(to_string(ParamValue{StringList{"a", "b"}}), "[\"a\", \"b\"]");
  EXPECT_EQ(param_type_name(ParamType::kStringList), "list of strings");
}

}  // namespace
}  // namespace chimera
