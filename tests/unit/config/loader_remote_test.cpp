// The loader on `exports:`, `imports:` and `dds:` (contract section 4): what it reads, its
// defaults, and one "file:line: key: problem" message for each kind of bad input.

#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/spec_writer.hpp"
#include "unit/config/fake_modules.hpp"
#include "unit/config/load_error.hpp"

namespace chimera {
namespace {

using test::error_of;

constexpr const char* kHead = "subsystem: s\ntasks:\n  - {name: a, module: visual_servo}\n";

SubsystemSpec load_ok(const std::string& text) {
  auto r = load_subsystem_text(text, "pid.yaml", test::config_test_registry());
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? *std::move(r) : SubsystemSpec{};
}

TEST(LoaderRemote, FileWithoutTheKeysHasNoRemoteVariables) {
  const SubsystemSpec s = load_ok(kHead);
  EXPECT_FALSE(s.has_remote_variables());
  EXPECT_EQ(s.dds.domain, 0U);
  EXPECT_EQ(s.dds.partition, "");
}

TEST(LoaderRemote, ExportsImportsAndDdsAreRead) {
  const SubsystemSpec s = load_ok(std::string(kHead) +
                                  "exports: [x_d, x_goal]\n"
                                  "imports:\n"
                                  "  x_m: { type: f64, count: 6, max_age: 50ms }\n"
                                  "  theta_m: { type: f64, count: 7, max_age: 2ms, reliability: best_effort,\n"
                                  "             durability: transient_local }\n"
                                  "dds: { domain: 7, partition: cell_3 }\n");
  ASSERT_EQ(s.exports.size(), 2U);
  EXPECT_EQ(s.exports[0].variable, "x_d");
  EXPECT_EQ(s.exports[0].loc.line, 4);
  EXPECT_EQ(s.exports[1].variable, "x_goal");
  ASSERT_EQ(s.imports.size(), 2U);
  const ImportSpec& x_m = s.imports[0];
  EXPECT_EQ(x_m.variable, "x_m");
  EXPECT_EQ(x_m.type, ElemType::kF64);
  EXPECT_EQ(x_m.count, 6U);
  EXPECT_EQ(x_m.max_age_ns, 50'000'000);
  EXPECT_EQ(x_m.reliability, DdsReliability::kReliable);  // the defaults
  EXPECT_EQ(x_m.durability, DdsDurability::kVolatile);
  EXPECT_EQ(x_m.loc.line, 6);
  const ImportSpec& theta = s.imports[1];
  EXPECT_EQ(theta.count, 7U);
  EXPECT_EQ(theta.max_age_ns, 2'000'000);
  EXPECT_EQ(theta.reliability, DdsReliability::kBestEffort);
  EXPECT_EQ(theta.durability, DdsDurability::kTransientLocal);
  EXPECT_EQ(s.find_import("theta_m"), &theta);
  EXPECT_EQ(s.find_import("x_d"), nullptr);
  EXPECT_EQ(s.dds.domain, 7U);
  EXPECT_EQ(s.dds.partition, "cell_3");
  EXPECT_TRUE(s.has_remote_variables());
}

TEST(LoaderRemote, EmptyPartitionIsDdsDefaultPartition) {
  EXPECT_EQ(load_ok(std::string(kHead) + "dds: { domain: 3, partition: \"\" }\n").dds.partition, "");
}

TEST(LoaderRemote, BadExports) {
  const std::string head(kHead);
  EXPECT_EQ(error_of(head + "exports: x_d\n"),
            "pid.yaml:4: exports: must be a list of state variables, e.g. [x_m, theta_m], not \"x_d\"");
  EXPECT_EQ(error_of(head + "exports: [x_d, 9x]\n"),
            "pid.yaml:4: exports[1]: \"9x\" is not a valid variable (letters, digits and _, not starting with a digit)");
  EXPECT_EQ(error_of(head + "exports:\n  - x_d\n  - x_d\n"), "pid.yaml:6: exports[1]: x_d is listed twice");
}

TEST(LoaderRemote, BadImports) {
  const std::string head(kHead);
  EXPECT_EQ(error_of(head + "imports: [x_m]\n"), "pid.yaml:4: imports: imports must be a mapping, not a list");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { count: 6, max_age: 50ms }\n"),
            "pid.yaml:5: imports.x_m.type: missing (the element type, e.g. type: f64)");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { type: f63, count: 6, max_age: 50ms }\n"),
            "pid.yaml:5: imports.x_m.type: \"f63\" is not an element type");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { type: i32, count: 6, max_age: 50ms }\n"),
            "pid.yaml:5: imports.x_m.type: i32 cannot travel: imports are f64 (the wire format is "
            "std_msgs/msg/Float64MultiArray)");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { type: f64, count: 0, max_age: 50ms }\n"),
            "pid.yaml:5: imports.x_m.count: \"0\" is not an element count (a whole number from 1 to 1048576)");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { type: f64, count: 6 }\n"),
            "pid.yaml:5: imports.x_m.max_age: missing (how old the value may become before it is stale, e.g. "
            "max_age: 50ms)");
  EXPECT_EQ(error_of(head + "imports:\n  x_m:\n    type: f64\n    count: 6\n    max_age: 50 ms\n"),
            "pid.yaml:8: imports.x_m.max_age: \"50 ms\" is not a duration (use ns, us, ms or s, e.g. 10ms)");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { type: f64, count: 6, max_age: 0ms }\n"),
            "pid.yaml:5: imports.x_m.max_age: must be longer than 0");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { type: f64, count: 6, max_age: 5ms, reliability: sure }\n"),
            "pid.yaml:5: imports.x_m.reliability: \"sure\" is not one of reliable or best_effort");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { type: f64, count: 6, max_age: 5ms, durability: forever }\n"),
            "pid.yaml:5: imports.x_m.durability: \"forever\" is not one of volatile or transient_local");
  EXPECT_EQ(error_of(head + "imports:\n  x_m: { type: f64, count: 6, max_age: 5ms, depth: 3 }\n"),
            "pid.yaml:5: imports.x_m.depth: unknown key (known: type, count, max_age, reliability, durability)");
  EXPECT_EQ(error_of(head + "exports: [x_m]\nimports:\n  x_m: { type: f64, count: 6, max_age: 5ms }\n"),
            "pid.yaml:6: imports.x_m: x_m is exported too; a subsystem either publishes a variable or reads it "
            "from another");
}

TEST(LoaderRemote, BadDds) {
  const std::string head(kHead);
  EXPECT_EQ(error_of(head + "dds: 0\n"), "pid.yaml:4: dds: dds must be a mapping of keys, not \"0\"");
  EXPECT_EQ(error_of(head + "dds: { domain: 233 }\n"),
            "pid.yaml:4: dds.domain: \"233\" is not a DDS domain id (a whole number from 0 to 232)");
  EXPECT_EQ(error_of(head + "dds:\n  domain: 1\n  partition: cell_*\n"),
            "pid.yaml:6: dds.partition: \"cell_*\" holds a wildcard character (* ? [ ] \\); name one partition");
  EXPECT_EQ(error_of(head + "dds: { domain: 1, transport: udp }\n"),
            "pid.yaml:4: dds.transport: unknown key (known: domain, partition)");
}

TEST(LoaderRemote, WrittenBackTheKeysLoadTheSame) {
  const SubsystemSpec s = load_ok(std::string(kHead) +
                                  "exports: [x_d]\n"
                                  "imports:\n"
                                  "  x_m: { type: f64, count: 6, max_age: 50ms, reliability: best_effort }\n"
                                  "dds: { domain: 7, partition: cell_3 }\n");
  const SubsystemSpec back = load_ok(write_subsystem_yaml(s));
  ASSERT_EQ(back.exports.size(), 1U);
  EXPECT_EQ(back.exports[0].variable, "x_d");
  ASSERT_EQ(back.imports.size(), 1U);
  EXPECT_EQ(back.imports[0].count, 6U);
  EXPECT_EQ(back.imports[0].max_age_ns, 50'000'000);
  EXPECT_EQ(back.imports[0].reliability, DdsReliability::kBestEffort);
  EXPECT_EQ(back.imports[0].durability, DdsDurability::kVolatile);
  EXPECT_EQ(back.dds.domain, 7U);
  EXPECT_EQ(back.dds.partition, "cell_3");
}

}  // namespace
}  // namespace chimera
