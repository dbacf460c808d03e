// The subsystem file loader on bad files: each problem gives one "file:line: key: problem"
// message with the right line and key path, and the whole file is refused.

#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "unit/config/fake_modules.hpp"
#include "unit/config/load_error.hpp"

namespace chimera {
namespace {

using test::error_of;

// A task list to append to headers under test.
constexpr const char* kOneTask = "tasks:\n  - {name: a, module: visual_servo}\n";

// ---- the file as a whole -------------------------------------------------------------------

TEST(LoaderErrors, EmptyFile) {
  EXPECT_EQ(error_of(""), "pid.yaml:1: the file is empty (a subsystem file needs at least subsystem: and tasks:)");
  EXPECT_EQ(error_of("# only a comment\n\n"),
            "pid.yaml:1: the file is empty (a subsystem file needs at least subsystem: and tasks:)");
}

TEST(LoaderErrors, FileThatIsNotAMapping) {
  EXPECT_EQ(error_of("- a\n- b\n"),
            "pid.yaml:1: the file must be a mapping of keys (subsystem:, tasks:, ...), not a list");
  EXPECT_EQ(error_of("hello\n"),
            "pid.yaml:1: the file must be a mapping of keys (subsystem:, tasks:, ...), not \"hello\"");
}

TEST(LoaderErrors, YamlSyntaxError) {
  EXPECT_EQ(error_of("subsystem: s\ntasks: [a, b\nstart: x\n"),
            "pid.yaml:3: YAML syntax error: end of sequence flow not found");
  EXPECT_EQ(error_of("subsystem: s\n  bad: indent\n"), "pid.yaml:2: YAML syntax error: illegal map value");
}

// yaml-cpp 0.7's LoadAll never returns on these (jbeder/yaml-cpp#1040); the fuzzer found it
// (tests/fuzz/regressions/subsystem_file/yaml_cpp_1040_*).
TEST(LoaderErrors, AStrayCommaIsASyntaxErrorNotAHang) {
  constexpr const char* kStuck = "YAML syntax error: the parser cannot go on from here (a ',' outside [ ] or { }?)";
  EXPECT_EQ(error_of(","), std::string("pid.yaml:1: ") + kStuck);
  EXPECT_EQ(error_of("[a], b\n"), std::string("pid.yaml:1: ") + kStuck);
  EXPECT_EQ(error_of("# comment\n\n  ,\n"), std::string("pid.yaml:3: ") + kStuck);
}

TEST(LoaderErrors, MoreThanOneDocument) {
  EXPECT_EQ(error_of("subsystem: s\ntasks: []\n---\nsubsystem: t\n"),
            "pid.yaml:4: the file holds more than one YAML document (---); write one subsystem per file");
}

// ---- top-level keys ------------------------------------------------------------------------

TEST(LoaderErrors, UnknownTopLevelKey) {
  EXPECT_EQ(error_of(std::string("subsystem: s\nschedular: rm\n") + kOneTask),
            "pid.yaml:2: schedular: unknown key (known: subsystem, scheduler, cpus, plugins, constants, process, "
            "tasks, configurations, start, requests, exports, imports, dds)");
}

TEST(LoaderErrors, KeyWrittenTwice) {
  EXPECT_EQ(error_of(std::string("subsystem: s\nscheduler: rm\nscheduler: edf\n") + kOneTask),
            "pid.yaml:3: scheduler: written twice (first at line 2)");
}

TEST(LoaderErrors, MissingSubsystem) {
  EXPECT_EQ(error_of(std::string("# comment\nscheduler: rm\n") + kOneTask),
            "pid.yaml:2: subsystem: missing (name the subsystem, e.g. subsystem: arm)");
}

TEST(LoaderErrors, BadSubsystemName) {
  EXPECT_EQ(error_of(std::string("subsystem: my-arm\n") + kOneTask),
            "pid.yaml:1: subsystem: \"my-arm\" is not a valid subsystem name (letters, digits and _ only: it names "
            "the subsystem's shared memory)");
  EXPECT_EQ(error_of(std::string("subsystem: [a]\n") + kOneTask),
            "pid.yaml:1: subsystem: needs a text value, not a list");
  EXPECT_EQ(error_of(std::string("subsystem:\n") + kOneTask), "pid.yaml:1: subsystem: needs a text value, not nothing");
}

TEST(LoaderErrors, BadScheduler) {
  EXPECT_EQ(error_of(std::string("subsystem: s\nscheduler: fifo\n") + kOneTask),
            "pid.yaml:2: scheduler: \"fifo\" is not a scheduler (use rm, dm, edf or muf)");
}

TEST(LoaderErrors, BadCpus) {
  EXPECT_EQ(error_of(std::string("subsystem: s\ncpus: 1\n") + kOneTask),
            "pid.yaml:2: cpus: must be a non-empty list of cpu numbers, e.g. [0, 1], not \"1\"");
  EXPECT_EQ(error_of(std::string("subsystem: s\ncpus: [0, -1]\n") + kOneTask),
            "pid.yaml:2: cpus[1]: \"-1\" is not a CPU number (a whole number >= 0)");
  EXPECT_EQ(error_of(std::string("subsystem: s\ncpus:\n  - 0\n  - 1.5\n") + kOneTask),
            "pid.yaml:4: cpus[1]: \"1.5\" is not a CPU number (a whole number >= 0)");
  EXPECT_EQ(error_of(std::string("subsystem: s\ncpus: [1, 1]\n") + kOneTask),
            "pid.yaml:2: cpus[1]: cpu 1 is listed twice");
}

TEST(LoaderErrors, BadPlugins) {
  EXPECT_EQ(error_of(std::string("subsystem: s\nplugins: {a: b}\n") + kOneTask),
            "pid.yaml:2: plugins: must be a list of library names, e.g. [libmy_modules.so], not a mapping");
  EXPECT_EQ(error_of(std::string("subsystem: s\nplugins:\n  - liba.so\n  - [x]\n") + kOneTask),
            "pid.yaml:4: plugins[1]: needs a text value, not a list");
}

TEST(LoaderErrors, BadConstants) {
  EXPECT_EQ(error_of(std::string("subsystem: s\nconstants: [1, 2]\n") + kOneTask),
            "pid.yaml:2: constants: constants must be a mapping, not a list");
  EXPECT_EQ(error_of(std::string("subsystem: s\nconstants:\n  ndof: six\n") + kOneTask),
            "pid.yaml:3: constants.ndof: \"six\" is not a number or a list of numbers");
  EXPECT_EQ(error_of(std::string("subsystem: s\nconstants:\n  home: [0, x]\n") + kOneTask),
            "pid.yaml:3: constants.home[1]: \"x\" is not a number");
  EXPECT_EQ(error_of(std::string("subsystem: s\nconstants:\n  home: []\n") + kOneTask),
            "pid.yaml:3: constants.home: a list is not a number or a list of numbers");
  EXPECT_EQ(error_of(std::string("subsystem: s\nconstants:\n  2x: 1\n") + kOneTask),
            "pid.yaml:3: constants.2x: not a valid variable name (letters, digits and _, not starting with a digit)");
  EXPECT_EQ(error_of(std::string("subsystem: s\nconstants:\n  a: 1\n  a: 2\n") + kOneTask),
            "pid.yaml:4: constants.a: written twice (first at line 3)");
}

// A variable's name lives in a 64-byte field of the table's shared memory: the loader refuses a
// longer one at its line, where `run` once refused it with no line at all.
TEST(LoaderErrors, VariableNamesLongerThanTheTableHoldsAreRefusedAtTheirLine) {
  const std::string at_limit(kMaxVariableName, 'v');
  const std::string over(kMaxVariableName + 1, 'v');
  const std::string limit_note = " is longer than 63 characters (the state variable table's limit)";
  EXPECT_TRUE(load_subsystem_text("subsystem: s\nconstants:\n  " + at_limit + ": 1\n" + kOneTask, "pid.yaml",
                                  test::config_test_registry())
                  .ok());
  EXPECT_EQ(error_of("subsystem: s\nconstants:\n  " + over + ": 1\n" + kOneTask),
            "pid.yaml:3: constants." + over + ": variable name \"" + over + "\"" + limit_note);
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: v\n    module: visual_servo\n    rename: { x_d: " + over + " }\n"),
            "pid.yaml:5: tasks[0].rename.x_d: variable name \"" + over + "\"" + limit_note);
  EXPECT_EQ(error_of("subsystem: s\nimports:\n  " + over + ": { type: f64, count: 1, max_age: 5ms }\n" + kOneTask),
            "pid.yaml:3: imports." + over + ": variable name \"" + over + "\"" + limit_note);
  const std::string port(kMaxVariableName + 1, 'p');
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: l\n    module: long_port\n"),
            "pid.yaml:4: tasks[0].module: port " + port + " of long_port names variable " + port +
                ", longer than 63 characters (the state variable table's limit): rename it");
  EXPECT_TRUE(load_subsystem_text("subsystem: s\ntasks:\n  - name: l\n    module: long_port\n    rename: { " + port +
                                      ": y }\n",
                                  "pid.yaml", test::config_test_registry())
                  .ok());
}

// ---- tasks ---------------------------------------------------------------------------------

TEST(LoaderErrors, MissingOrEmptyTasks) {
  EXPECT_EQ(error_of("subsystem: s\n"), "pid.yaml:1: tasks: missing (a subsystem needs at least one task)");
  EXPECT_EQ(error_of("subsystem: s\ntasks: []\n"),
            "pid.yaml:2: tasks: must be a non-empty list of tasks (- name: ...), not a list");
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  a: 1\n"),
            "pid.yaml:2: tasks: must be a non-empty list of tasks (- name: ...), not a mapping");
}

TEST(LoaderErrors, TaskThatIsNotAMapping) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - {name: a, module: visual_servo}\n  - traj\n"),
            "pid.yaml:4: tasks[1]: a task must be a mapping of keys, not \"traj\"");
}

TEST(LoaderErrors, UnknownTaskKey) {
  EXPECT_EQ(error_of(R"(subsystem: s
tasks:
  - name: a
    module: visual_servo
    perod: 10ms
)"),
            "pid.yaml:5: tasks[0].perod: unknown key (known: name, module, period, frequency, deadline, criticality, "
            "wcet, cpu, priority, late, virtual_exec, server, params, rename, process)");
}

TEST(LoaderErrors, MissingNameOrModule) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - module: visual_servo\n"),
            "pid.yaml:3: tasks[0].name: missing (every task has a unique name)");
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: a\n"),
            "pid.yaml:3: tasks[0].module: missing (the module type this task runs, e.g. pid_joint)");
}

TEST(LoaderErrors, BadTaskName) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - {name: my task, module: visual_servo}\n"),
            "pid.yaml:3: tasks[0].name: \"my task\" is not a valid task name (letters, digits and _, not starting "
            "with a digit)");
}

TEST(LoaderErrors, DuplicateTask) {
  EXPECT_EQ(error_of(R"(subsystem: s
tasks:
  - name: a
    module: visual_servo
  - name: b
    module: visual_servo
  - name: a
    module: inv_kin
)"),
            "pid.yaml:7: tasks[2].name: task a is already defined at line 3");
  // The line is the name's, wherever it sits in the task.
  EXPECT_EQ(error_of(R"(subsystem: s
tasks:
  - name: a
    module: visual_servo
  - module: inv_kin
    period: 1ms
    name: a
)"),
            "pid.yaml:7: tasks[1].name: task a is already defined at line 3");
}

TEST(LoaderErrors, UnknownModule) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: a\n    module: pidd\n"),
            "pid.yaml:4: tasks[0].module: no module named pidd (known: any_logger, bad_sized, damped_least_squares, "
            "f32_logger, "
            "fwd_kin_jacobian, inv_kin, join_weighted_average, joint_traj_gen, long_port, pid_joint, robot_position, "
            "robot_torque, time_integrator, visual_servo)");
  const Registry empty;
  auto r = load_subsystem_text("subsystem: s\ntasks:\n  - name: a\n    module: pid\n", "e.yaml", empty);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "e.yaml:4: tasks[0].module: no module named pid (the module library is empty)");
}

// The contract's example message, at its line and key path.
TEST(LoaderErrors, PeriodWithASpaceIsNotADuration) {
  EXPECT_EQ(error_of(R"(# PID joint control
subsystem: pid
tasks:
  - name: traj
    module: joint_traj_gen
    period: 10ms
  - name: robot
    module: robot_torque
    period: 1ms

  # the controller
  - name: pid
    module: pid_joint
    period: 10 ms
)"),
            "pid.yaml:14: tasks[2].period: \"10 ms\" is not a duration (use ns, us, ms or s, e.g. 10ms)");
}

TEST(LoaderErrors, SubsystemNamesThatEveryCommandCanUse) {
  // verify must refuse what run or analyze would (their shared memory names add to it).
  const std::string tail = "\ntasks:\n  - {name: a, module: visual_servo, period: 1ms}\n";
  EXPECT_EQ(error_of("subsystem: " + std::string(161, 'n') + tail),
            "pid.yaml:1: subsystem: a subsystem name has 1 to 160 characters, this one 161");
  EXPECT_TRUE(load_subsystem_text("subsystem: " + std::string(160, 'n') + tail, "pid.yaml",
                                  test::config_test_registry())
                  .ok());
}

TEST(LoaderErrors, BadPeriods) {
  const std::string head = "subsystem: s\ntasks:\n  - name: a\n    module: visual_servo\n";
  EXPECT_EQ(error_of(head + "    period: 0ms\n"), "pid.yaml:5: tasks[0].period: must be greater than zero");
  EXPECT_EQ(error_of(head + "    period: -1ms\n"),
            "pid.yaml:5: tasks[0].period: \"-1ms\" is negative; a duration is >= 0");
  EXPECT_EQ(error_of(head + "    period: 10\n"),
            "pid.yaml:5: tasks[0].period: \"10\" is not a duration (use ns, us, ms or s, e.g. 10ms)");
  EXPECT_EQ(error_of(head + "    period: [10ms]\n"),
            "pid.yaml:5: tasks[0].period: a list is not a duration (use ns, us, ms or s, e.g. 10ms)");
  EXPECT_EQ(error_of(head + "    period:\n"),
            "pid.yaml:5: tasks[0].period: nothing is not a duration (use ns, us, ms or s, e.g. 10ms)");
  // A period that cannot run (and would make analyze's measuring run take hours).
  EXPECT_EQ(error_of(head + "    period: 1ns\n"),
            "pid.yaml:5: tasks[0].period: 1ns is shorter than 10 µs, the shortest period a task can be released at");
  EXPECT_EQ(error_of(head + "    frequency: 200kHz\n"),
            "pid.yaml:5: tasks[0].frequency: 200kHz (a period of 5 µs) is shorter than 10 µs, the shortest period a "
            "task can be released at");
  EXPECT_TRUE(load_subsystem_text(head + "    period: 10us\n", "pid.yaml", test::config_test_registry()).ok())
      << "the shortest period is allowed";
}

TEST(LoaderErrors, PeriodAndFrequencyTogether) {
  EXPECT_EQ(
      error_of("subsystem: s\ntasks:\n  - name: a\n    module: visual_servo\n    period: 1ms\n    frequency: 1kHz\n"),
      "pid.yaml:6: tasks[0].frequency: give period or frequency, not both");
}

TEST(LoaderErrors, BadFrequency) {
  const std::string head = "subsystem: s\ntasks:\n  - name: a\n    module: visual_servo\n";
  EXPECT_EQ(error_of(head + "    frequency: 100 Hz\n"),
            "pid.yaml:5: tasks[0].frequency: \"100 Hz\" is not a frequency (use Hz or kHz, e.g. 100Hz)");
  EXPECT_EQ(error_of(head + "    frequency: 0Hz\n"),
            "pid.yaml:5: tasks[0].frequency: \"0Hz\" is not a usable frequency (must be > 0)");
}

TEST(LoaderErrors, BadDeadlineAndWcet) {
  const std::string head = "subsystem: s\ntasks:\n  - name: a\n    module: visual_servo\n    period: 10ms\n";
  EXPECT_EQ(error_of(head + "    deadline: soon\n"),
            "pid.yaml:6: tasks[0].deadline: \"soon\" is not a duration (use ns, us, ms or s, e.g. 10ms)");
  EXPECT_EQ(error_of(head + "    deadline: 0s\n"), "pid.yaml:6: tasks[0].deadline: must be greater than zero");
  EXPECT_EQ(error_of(head + "    wcet: 2 ms\n"),
            "pid.yaml:6: tasks[0].wcet: \"2 ms\" is not a duration (use ns, us, ms or s, e.g. 10ms)");
  EXPECT_EQ(error_of(head + "    wcet: 0us\n"), "pid.yaml:6: tasks[0].wcet: must be greater than zero");
}

TEST(LoaderErrors, BadCriticality) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - {name: a, module: visual_servo, criticality: firm}\n"),
            "pid.yaml:3: tasks[0].criticality: \"firm\" is not a criticality (use hard or soft)");
}

TEST(LoaderErrors, BadSchedulingKeys) {
  const std::string periodic = "subsystem: s\ntasks:\n  - name: a\n    module: visual_servo\n    period: 10ms\n";
  const std::string aperiodic = "subsystem: s\ntasks:\n  - name: a\n    module: visual_servo\n";
  EXPECT_EQ(error_of(periodic + "    priority: 1.5\n"),
            "pid.yaml:6: tasks[0].priority: \"1.5\" is not a whole number from -1000 to 1000");
  EXPECT_EQ(error_of(periodic + "    priority: 5000\n"),
            "pid.yaml:6: tasks[0].priority: \"5000\" is not a whole number from -1000 to 1000");
  EXPECT_EQ(error_of(periodic + "    late: later\n"),
            "pid.yaml:6: tasks[0].late: \"later\" is not a late-cycle policy (use run or skip)");
  EXPECT_EQ(error_of(aperiodic + "    late: skip\n"),
            "pid.yaml:5: tasks[0].late: only a periodic task has releases to run late or skip");
  EXPECT_EQ(error_of(periodic + "    virtual_exec: 2 ms\n"),
            "pid.yaml:6: tasks[0].virtual_exec: \"2 ms\" is not a duration (use ns, us, ms or s, e.g. 10ms)");
  EXPECT_EQ(error_of(periodic + "    server: {budget: 1ms, period: 10ms}\n"),
            "pid.yaml:6: tasks[0].server: a server is for an aperiodic task (this one has a period; remove one of "
            "them)");
  EXPECT_EQ(error_of(aperiodic + "    server: {budget: 1ms}\n"),
            "pid.yaml:5: tasks[0].server.period: missing (a server has a budget and a period, e.g. { budget: 1ms, "
            "period: 10ms })");
  EXPECT_EQ(error_of(aperiodic + "    server: {budget: 1ms, period: 10ms, kind: deferrable}\n"),
            "pid.yaml:5: tasks[0].server.kind: unknown key (known: budget, period)");
  EXPECT_EQ(error_of(aperiodic + "    server: {budget: 0ms, period: 10ms}\n"),
            "pid.yaml:5: tasks[0].server.budget: must be greater than zero");
  EXPECT_EQ(error_of(aperiodic + "    server: {budget: 11ms, period: 10ms}\n"),
            "pid.yaml:5: tasks[0].server.budget: the budget cannot be longer than the server's period");
  // A server replenishes on a timer: a task's period floor holds for it too.
  EXPECT_EQ(error_of(aperiodic + "    server: {budget: 1ns, period: 2ns}\n"),
            "pid.yaml:5: tasks[0].server.period: 2ns is shorter than 10 µs, the shortest period a server can "
            "replenish at");
  EXPECT_EQ(error_of(aperiodic + "    server: 10ms\n"),
            "pid.yaml:5: tasks[0].server: a server must be a mapping of keys, not \"10ms\"");
}

TEST(LoaderErrors, BadCpu) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - {name: a, module: visual_servo, cpu: -2}\n"),
            "pid.yaml:3: tasks[0].cpu: \"-2\" is not a CPU number (a whole number >= 0)");
  EXPECT_EQ(error_of("subsystem: s\ncpus: [0, 1]\ntasks:\n  - name: a\n    module: visual_servo\n    cpu: 2\n"),
            "pid.yaml:6: tasks[0].cpu: cpu 2 is not one of the subsystem's cpus [0, 1]");
}

TEST(LoaderErrors, BadProcess) {
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - {name: a, module: visual_servo, process: 2d}\n"),
            "pid.yaml:3: tasks[0].process: \"2d\" is not a valid process name (letters, digits and _, not starting "
            "with a digit)");
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - name: a\n    module: visual_servo\n    process: [a, b]\n"),
            "pid.yaml:5: tasks[0].process: needs a text value, not a list");
  EXPECT_EQ(error_of(std::string("subsystem: s\nprocess: vision-1\n") + kOneTask),
            "pid.yaml:2: process: \"vision-1\" is not a valid process name (letters, digits and _, not starting "
            "with a digit)");
  EXPECT_EQ(error_of(std::string("subsystem: s\nprocess:\n") + kOneTask),
            "pid.yaml:2: process: needs a text value, not nothing");
  const std::string long_name(41, 'p');
  EXPECT_EQ(error_of("subsystem: s\ntasks:\n  - {name: a, module: visual_servo, process: " + long_name + "}\n"),
            "pid.yaml:3: tasks[0].process: \"" + long_name + "\" is longer than 40 characters");
}

}  // namespace
}  // namespace chimera
