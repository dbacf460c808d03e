// The subsystem file loader on names that refer to something else: parameters and ports of the
// task's module, tasks named by configurations, the configuration named by start.

#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "unit/config/fake_modules.hpp"
#include "unit/config/load_error.hpp"

namespace chimera {
namespace {

const Registry& registry() { return test::config_test_registry(); }

using test::error_of;

// A pid task whose params: block starts on line 5 (its first entry on line 6).
const std::string kPidHead = "subsystem: s\ntasks:\n  - name: pid\n    module: pid_joint\n    params:\n";

TEST(LoaderReferences, UnknownParameterListsTheKnownOnes) {
  EXPECT_EQ(error_of(kPidHead + "      kp: 1\n      kq: 2\n"),
            "pid.yaml:7: tasks[0].params.kq: unknown parameter of pid_joint (known: caps, enabled, form, kd, ki, kp, "
            "label, limits)");
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: fk\n    module: fwd_kin_jacobian\n    params: {gain: 1}\n"),
            "pid.yaml:5: tasks[0].params.gain: unknown parameter (fwd_kin_jacobian takes none)");
}

// A declared range or list of choices (module/param_rule.hpp): what init would refuse is refused
// by the loader, so `chimera verify` names the line.
TEST(LoaderReferences, AValueOutsideItsDeclaredRangeIsRefusedWithItsLine) {
  EXPECT_EQ(error_of(kPidHead + "      kd: 1\n      kp: -1\n"),
            "pid.yaml:7: tasks[0].params.kp: -1 given: must be >= 0");
  EXPECT_EQ(error_of(kPidHead + "      caps: [10, 0, 5]\n"),
            "pid.yaml:6: tasks[0].params.caps: [10, 0, 5] given: element 1 is 0, must be > 0");
  EXPECT_EQ(error_of(kPidHead + "      form: pi\n"),
            "pid.yaml:6: tasks[0].params.form: \"pi\" given: must be one of: pid, pd");
  const auto bounds =
      load_subsystem_text(kPidHead + "      kp: 0\n      form: pd\n      caps: [1]\n", "pid.yaml", registry());
  EXPECT_TRUE(bounds.ok()) << "the bounds themselves pass: " << (bounds.ok() ? "" : bounds.error().message);
}

TEST(LoaderReferences, WrongParameterTypeNamesTheExpectedType) {
  EXPECT_EQ(error_of(kPidHead + "      kp: high\n"),
            "pid.yaml:6: tasks[0].params.kp: \"high\" is a string, but kp of pid_joint takes a number");
  EXPECT_EQ(error_of(kPidHead + "      kp: \"100\"\n"),
            "pid.yaml:6: tasks[0].params.kp: \"100\" is a string, but kp of pid_joint takes a number");
  EXPECT_EQ(error_of(kPidHead + "      enabled: 1\n"),
            "pid.yaml:6: tasks[0].params.enabled: 1 is a number, but enabled of pid_joint takes a boolean (true or "
            "false)");
  EXPECT_EQ(error_of(kPidHead + "      label: [1]\n"),
            "pid.yaml:6: tasks[0].params.label: [1] is a list of numbers, but label of pid_joint takes a string");
  EXPECT_EQ(error_of(kPidHead + "      limits: 5\n"),
            "pid.yaml:6: tasks[0].params.limits: 5 is a number, but limits of pid_joint takes a list of numbers");
  EXPECT_EQ(error_of(kPidHead + "      limits: [[1], [2]]\n"),
            "pid.yaml:6: tasks[0].params.limits: [[1], [2]] is a list of lists of numbers, but limits of pid_joint "
            "takes a list of numbers");
}

TEST(LoaderReferences, MalformedParameterValues) {
  EXPECT_EQ(error_of(kPidHead + "      limits: [1, a]\n"),
            "pid.yaml:6: tasks[0].params.limits[1]: \"a\" is not a number");
  EXPECT_EQ(error_of(kPidHead + "      kp:\n"), "pid.yaml:6: tasks[0].params.kp: needs a value");
  EXPECT_EQ(error_of(kPidHead + "      kp: {a: 1}\n"),
            "pid.yaml:6: tasks[0].params.kp: a mapping is not a parameter value (use a number, true/false, text or a "
            "list)");
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: t\n    module: joint_traj_gen\n    params:\n"
                     "      waypoints:\n        - [1, 2]\n        - 3\n"),
            "pid.yaml:8: tasks[0].params.waypoints[1]: \"3\" is not a row (a matrix is a list of lists of numbers)");
  EXPECT_EQ(error_of(kPidHead + "      kp: 1\n      kp: 2\n"),
            "pid.yaml:7: tasks[0].params.kp: written twice (first at line 6)");
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: pid\n    module: pid_joint\n    params: [kp, 1]\n"),
            "pid.yaml:5: tasks[0].params: params must be a mapping, not a list");
}

TEST(LoaderReferences, RenameOfAPortTheModuleDoesNotHave) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: v\n    module: visual_servo\n    rename:\n      x_q: x_goal\n"),
            "pid.yaml:6: tasks[0].rename.x_q: visual_servo has no port x_q (ports: x_m, x_d)");
}

TEST(LoaderReferences, RenameToABadVariableName) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: v\n    module: visual_servo\n    rename: { x_d: x-goal }\n"),
            "pid.yaml:5: tasks[0].rename.x_d: \"x-goal\" is not a valid variable name (letters, digits and _, not "
            "starting with a digit)");
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: v\n    module: visual_servo\n    rename: x_d\n"),
            "pid.yaml:5: tasks[0].rename: rename must be a mapping, not \"x_d\"");
}

TEST(LoaderReferences, RenameThatBindsTwoPortsToOneVariable) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: v\n    module: visual_servo\n    rename: { x_d: x_m }\n"),
            "pid.yaml:5: tasks[0].rename.x_d: ports x_d and x_m of v would both be bound to variable x_m");
}

TEST(LoaderReferences, RenameSeesPortsThatDependOnParameters) {
  const std::string head = "subsystem: s\ntasks:\n  - name: j\n    module: join_weighted_average\n";
  EXPECT_EQ(error_of(head + "    rename: { in_2: c }\n"),
            "pid.yaml:5: tasks[0].rename.in_2: join_weighted_average has no port in_2 (ports: ndof, in_0, in_1, out)");
  auto r = load_subsystem_text(head + "    params: { inputs: 3 }\n    rename: { in_2: c }\n", "pid.yaml", registry());
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->tasks[0].variable_of("in_2"), "c");
}

const std::string kTwoTasks =
    "subsystem: s\ntasks:\n  - {name: a, module: visual_servo}\n  - {name: b, module: inv_kin}\n";

TEST(LoaderReferences, ConfigurationNamingAnUnknownTask) {
  EXPECT_EQ(error_of(kTwoTasks + "configurations:\n  one: [a, c]\n"),
            "pid.yaml:6: configurations.one[1]: no task named c (tasks: a, b)");
  EXPECT_EQ(error_of(kTwoTasks + "configurations:\n  one:\n    - a\n    - bb\n"),
            "pid.yaml:8: configurations.one[1]: no task named bb (tasks: a, b)");
}

TEST(LoaderReferences, ConfigurationListingATaskTwice) {
  EXPECT_EQ(error_of(kTwoTasks + "configurations:\n  one: [a, b, a]\n"),
            "pid.yaml:6: configurations.one[2]: task a is listed twice");
}

TEST(LoaderReferences, BadConfigurations) {
  EXPECT_EQ(error_of(kTwoTasks + "configurations: [a, b]\n"),
            "pid.yaml:5: configurations: configurations must be a mapping, not a list");
  EXPECT_EQ(error_of(kTwoTasks + "configurations: {}\n"),
            "pid.yaml:5: configurations: needs at least one configuration (or leave the key out: all tasks form one)");
  EXPECT_EQ(error_of(kTwoTasks + "configurations:\n  one: a\n"),
            "pid.yaml:6: configurations.one: must be a list of task names, e.g. [traj, pid, robot], not \"a\"");
  EXPECT_EQ(error_of(kTwoTasks + "configurations:\n  one: [a]\n  one: [b]\n"),
            "pid.yaml:7: configurations.one: written twice (first at line 6)");
  EXPECT_EQ(error_of(kTwoTasks + "configurations:\n  the-one: [a]\n"),
            "pid.yaml:6: configurations.the-one: not a valid configuration name (letters, digits and _, not starting "
            "with a digit)");
}

TEST(LoaderReferences, StartNamingAnUnknownConfiguration) {
  EXPECT_EQ(error_of(kTwoTasks + "configurations:\n  one: [a]\n  two: [b]\nstart: three\n"),
            "pid.yaml:8: start: no configuration named three (configurations: one, two)");
  EXPECT_EQ(error_of(kTwoTasks + "start: standard\n"),
            "pid.yaml:5: start: no configuration named standard (configurations: default)");
  EXPECT_EQ(error_of(kTwoTasks + "start: [one]\n"), "pid.yaml:5: start: needs a text value, not a list");
}

}  // namespace
}  // namespace chimera
