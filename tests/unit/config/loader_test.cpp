// The subsystem file loader on good files: what it reads, and the defaults it fills in.

#include "chimera/config/loader.hpp"

#include <string>

#include <gtest/gtest.h>

#include "unit/config/fake_modules.hpp"

namespace chimera {
namespace {

const std::string kData = CHIMERA_CONFIG_TEST_DATA;

const Registry& registry() { return test::config_test_registry(); }

SubsystemSpec load_ok(std::string_view text) {
  auto r = load_subsystem_text(text, "test.yaml", registry());
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? *std::move(r) : SubsystemSpec{};
}

TEST(LoadSubsystem, Figure4FileAndItsDefaults) {
  auto r = load_subsystem_file(kData + "/figure4.yaml", registry());
  ASSERT_TRUE(r.ok()) << r.error().message;
  const SubsystemSpec& s = *r;
  EXPECT_EQ(s.name, "pid_joint_control");
  EXPECT_EQ(s.file, kData + "/figure4.yaml");
  EXPECT_EQ(s.scheduler, SchedulerKind::kRm);
  EXPECT_TRUE(s.cpus.empty());
  ASSERT_EQ(s.tasks.size(), 3U);

  const TaskSpec& traj = s.tasks[0];
  EXPECT_EQ(traj.name, "traj");
  EXPECT_EQ(traj.module, "joint_traj_gen");
  EXPECT_EQ(traj.period_ns, 10'000'000);
  EXPECT_EQ(traj.deadline_ns, 10'000'000);  // the period
  EXPECT_EQ(traj.criticality, Criticality::kHard);
  EXPECT_FALSE(traj.wcet_ns.has_value());
  EXPECT_FALSE(traj.cpu.has_value());
  EXPECT_EQ(traj.loc.file, kData + "/figure4.yaml");
  EXPECT_EQ(traj.loc.line, 5);

  const TaskSpec& pid = s.tasks[1];
  EXPECT_EQ(pid.period_ns, 1'000'000);  // frequency: 1kHz
  EXPECT_EQ(pid.params.number("kp"), 120.0);
  EXPECT_EQ(pid.params.number("kd"), 12.0);
  EXPECT_EQ(pid.params.number("ki", -1), 0.0);  // declared default
  EXPECT_TRUE(pid.params.flag("enabled"));
  EXPECT_EQ(pid.params.text("label"), "pid");
  EXPECT_TRUE(pid.params.has("limits"));

  // No configurations: one named "default" holds every task, and it is the start.
  ASSERT_EQ(s.configurations.size(), 1U);
  EXPECT_EQ(s.configurations[0].name, "default");
  EXPECT_EQ(s.configurations[0].tasks, (std::vector<std::string>{"traj", "pid", "robot"}));
  EXPECT_EQ(s.start, "default");
}

TEST(LoadSubsystem, ProcessesAndTheirDefault) {
  // No process: anywhere: every task in the chimera run process, as before.
  const SubsystemSpec plain = load_ok("subsystem: s\ntasks:\n  - {name: a, module: visual_servo}\n");
  EXPECT_EQ(plain.default_process, "main");
  EXPECT_EQ(plain.tasks[0].process, "main");
  EXPECT_FALSE(plain.uses_module_processes());
  // A task's own process:, and the top-level default for the others.
  const SubsystemSpec s = load_ok(R"(subsystem: s
process: vision
tasks:
  - {name: a, module: visual_servo}
  - {name: b, module: visual_servo, process: main}
  - {name: c, module: visual_servo, process: crashy}
)");
  EXPECT_EQ(s.default_process, "vision");
  EXPECT_EQ(s.tasks[0].process, "vision");
  EXPECT_EQ(s.tasks[1].process, "main");
  EXPECT_EQ(s.tasks[2].process, "crashy");
  EXPECT_TRUE(s.uses_module_processes());
}

TEST(LoadSubsystem, Figures8And9File) {
  auto r = load_subsystem_file(kData + "/figures8_9.yaml", registry());
  ASSERT_TRUE(r.ok()) << r.error().message;
  const SubsystemSpec& s = *r;
  EXPECT_EQ(s.scheduler, SchedulerKind::kMuf);
  EXPECT_EQ(s.cpus, (std::vector<int>{0, 1}));
  ASSERT_EQ(s.constants.size(), 1U);
  EXPECT_EQ(s.constants[0].first, "payload_kg");
  EXPECT_EQ(s.constants[0].second, (std::vector<double>{0.5}));
  const TaskSpec* vision = s.find_task("vision");
  ASSERT_NE(vision, nullptr);
  EXPECT_EQ(vision->period_ns, 30'000'000);
  EXPECT_EQ(vision->deadline_ns, 30'000'000);
  EXPECT_EQ(vision->criticality, Criticality::kSoft);
  EXPECT_EQ(vision->wcet_ns, 2'000'000);
  EXPECT_EQ(vision->cpu, 1);
  EXPECT_EQ(vision->params.number("gain"), 0.5);
  EXPECT_TRUE(vision->rename.empty());
  ASSERT_EQ(s.configurations.size(), 2U);
  EXPECT_EQ(s.configurations[0].name, "standard");
  EXPECT_EQ(s.configurations[0].tasks, (std::vector<std::string>{"vision", "fk", "ik", "robot"}));
  EXPECT_EQ(s.configurations[0].loc.line, 35);
  EXPECT_EQ(s.configurations[1].name, "near_singularity");
  EXPECT_EQ(s.start, "standard");
}

TEST(LoadSubsystem, EverySchedulerName) {
  for (auto kind : {SchedulerKind::kRm, SchedulerKind::kDm, SchedulerKind::kEdf, SchedulerKind::kMuf}) {
    const std::string text = "subsystem: s\nscheduler: " + std::string(scheduler_name(kind)) +
                             "\ntasks:\n  - {name: v, module: visual_servo}\n";
    EXPECT_EQ(load_ok(text).scheduler, kind);
  }
  EXPECT_EQ(criticality_name(Criticality::kHard), "hard");
  EXPECT_EQ(criticality_name(Criticality::kSoft), "soft");
}

TEST(LoadSubsystem, AperiodicTasksAndExplicitDeadlines) {
  const auto s = load_ok(R"(subsystem: s
tasks:
  - name: a
    module: visual_servo
  - name: b
    module: visual_servo
    deadline: 2.5ms
  - name: c
    module: visual_servo
    period: 10ms
    deadline: 20ms
    criticality: soft
)");
  EXPECT_FALSE(s.tasks[0].period_ns.has_value());
  EXPECT_EQ(s.tasks[0].deadline_ns, 0);  // aperiodic, no deadline given: none
  EXPECT_FALSE(s.tasks[1].period_ns.has_value());
  EXPECT_EQ(s.tasks[1].deadline_ns, 2'500'000);
  EXPECT_EQ(s.tasks[2].deadline_ns, 20'000'000);  // arbitrary deadlines are allowed
  EXPECT_EQ(s.tasks[2].criticality, Criticality::kSoft);
}

TEST(LoadSubsystem, SchedulingKeysAndTheirDefaults) {
  const auto s = load_ok(R"(subsystem: s
scheduler: muf
tasks:
  - {name: hard, module: visual_servo, period: 1ms}
  - {name: soft, module: visual_servo, period: 1ms, criticality: soft}
  - name: tuned
    module: visual_servo
    period: 2ms
    criticality: soft
    late: run
    priority: -3
    virtual_exec: 300us
  - name: events
    module: visual_servo
    server: { budget: 1ms, period: 10ms }
  - name: events_by_deadline
    module: visual_servo
    deadline: 4ms
    server: { budget: 1ms, period: 10ms }
)");
  EXPECT_EQ(s.tasks[0].late, LatePolicy::kRun);   // a hard task runs every release
  EXPECT_EQ(s.tasks[1].late, LatePolicy::kSkip);  // a soft one skips what it missed
  EXPECT_EQ(s.tasks[0].priority, 0);
  EXPECT_EQ(s.tasks[0].virtual_exec_ns, 0);
  EXPECT_FALSE(s.tasks[0].server.has_value());
  EXPECT_EQ(s.tasks[2].late, LatePolicy::kRun);
  EXPECT_EQ(s.tasks[2].priority, -3);
  EXPECT_EQ(s.tasks[2].virtual_exec_ns, 300'000);
  ASSERT_TRUE(s.tasks[3].server.has_value());
  EXPECT_EQ(s.tasks[3].server->budget_ns, 1'000'000);
  EXPECT_EQ(s.tasks[3].server->period_ns, 10'000'000);
  EXPECT_EQ(s.tasks[3].deadline_ns, 10'000'000);  // an event is served within the server's period
  EXPECT_EQ(s.tasks[4].deadline_ns, 4'000'000);
  EXPECT_EQ(late_policy_name(LatePolicy::kRun), "run");
  EXPECT_EQ(late_policy_name(LatePolicy::kSkip), "skip");
}

TEST(LoadSubsystem, ParameterValuesOfEveryType) {
  const auto s = load_ok(R"(subsystem: s
tasks:
  - name: pid
    module: pid_joint
    params:
      kp: 1e2
      enabled: false
      label: "7"
      limits: [10, 20.5, -3]
  - name: traj
    module: joint_traj_gen
    params:
      waypoints: [[0, 1], [2, 3, 4]]
  - name: empty
    module: joint_traj_gen
    params: { waypoints: [] }
)");
  const Params& p = s.tasks[0].params;
  EXPECT_EQ(p.number("kp"), 100.0);
  EXPECT_FALSE(p.flag("enabled", true));
  EXPECT_EQ(p.text("label"), "7");  // quoted: text, not a number
  EXPECT_EQ(p.vector("limits"), (Vector{10, 20.5, -3}));
  EXPECT_EQ(s.tasks[1].params.matrix("waypoints"), (Matrix{{0, 1}, {2, 3, 4}}));
  ASSERT_NE(s.tasks[2].params.find("waypoints"), nullptr);
  EXPECT_EQ(param_type_of(*s.tasks[2].params.find("waypoints")), ParamType::kMatrix);
}

TEST(LoadSubsystem, RenamesBindPortsToOtherVariables) {
  auto r = load_subsystem_file(kData + "/figure3_join.yaml", registry());
  ASSERT_TRUE(r.ok()) << r.error().message;
  const TaskSpec* join = r->find_task("join");
  ASSERT_NE(join, nullptr);
  EXPECT_EQ(join->variable_of("in_0"), "theta_d_a");
  EXPECT_EQ(join->variable_of("out"), "theta_d");
  EXPECT_EQ(join->variable_of("ndof"), "ndof");
}

TEST(LoadSubsystem, RenamesCanSwapTwoPorts) {
  const auto s = load_ok(R"(subsystem: s
tasks:
  - name: v
    module: visual_servo
    rename: { x_m: x_d, x_d: x_m }
)");
  EXPECT_EQ(s.tasks[0].variable_of("x_m"), "x_d");
  EXPECT_EQ(s.tasks[0].variable_of("x_d"), "x_m");
}

TEST(LoadSubsystem, ConstantsTakeNumbersAndLists) {
  const auto s = load_ok(R"(subsystem: s
constants:
  ndof: 6
  home: [0, 0.5, -1]
tasks:
  - {name: v, module: visual_servo}
)");
  ASSERT_EQ(s.constants.size(), 2U);
  EXPECT_EQ(s.constants[0], (std::pair<std::string, std::vector<double>>{"ndof", {6}}));
  EXPECT_EQ(s.constants[1], (std::pair<std::string, std::vector<double>>{"home", {0, 0.5, -1}}));
}

TEST(LoadSubsystem, StartDefaultsToTheFirstConfiguration) {
  const auto s = load_ok(R"(subsystem: s
tasks:
  - {name: a, module: visual_servo}
  - {name: b, module: visual_servo}
configurations:
  second: [b]
  first: [a, b]
  idle: []
)");
  EXPECT_EQ(s.start, "second");
  ASSERT_EQ(s.configurations.size(), 3U);
  EXPECT_EQ(s.configurations[1].tasks, (std::vector<std::string>{"a", "b"}));
  EXPECT_TRUE(s.configurations[2].tasks.empty());
}

TEST(LoadSubsystem, StartMayNameTheDefaultConfiguration) {
  const auto s = load_ok("subsystem: s\ntasks:\n  - {name: a, module: visual_servo}\nstart: default\n");
  EXPECT_EQ(s.start, "default");
}

TEST(LoadSubsystem, CpusAndPinning) {
  const auto s = load_ok(R"(subsystem: s
cpus: [2, 3]
plugins: [libextra.so, other.so]
tasks:
  - {name: a, module: visual_servo, cpu: 3}
)");
  EXPECT_EQ(s.cpus, (std::vector<int>{2, 3}));
  EXPECT_EQ(s.plugins, (std::vector<std::string>{"libextra.so", "other.so"}));
  EXPECT_EQ(s.tasks[0].cpu, 3);
}

TEST(LoadSubsystem, EmptyParamsAndRenameAreAllowed) {
  const auto s = load_ok("subsystem: s\ntasks:\n  - name: a\n    module: visual_servo\n    params:\n    rename:\n");
  EXPECT_EQ(s.tasks[0].params.number("gain"), 0.5);
  EXPECT_TRUE(s.tasks[0].rename.empty());
}

TEST(ReadPluginNames, ReadsOnlyThePluginList) {
  // The module is unknown to the registry: plugin names are read before modules are checked.
  auto r = read_plugin_names_text("subsystem: s\nplugins: [liba.so]\ntasks:\n  - {name: a, module: from_plugin}\n",
                                  "p.yaml");
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->size(), 1u);
  EXPECT_EQ((*r)[0].name, "liba.so");
  EXPECT_EQ((*r)[0].line, 2);
  EXPECT_EQ((*r)[0].key, "plugins[0]");
  auto none = read_plugin_names_file(kData + "/figure4.yaml");
  ASSERT_TRUE(none.ok()) << none.error().message;
  EXPECT_TRUE(none->empty());
  auto bad = read_plugin_names_text("subsystem: s\nplugins: libx.so\n", "p.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message,
            "p.yaml:2: plugins: must be a list of library names, e.g. [libmy_modules.so], not "
            "\"libx.so\"");
}

TEST(LoadSubsystemFile, MissingFileSaysSo) {
  auto r = load_subsystem_file(kData + "/no_such_file.yaml", registry());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, Errc::kInvalidInput);
  EXPECT_EQ(r.error().message, kData + "/no_such_file.yaml: cannot open the subsystem file (No such file or directory)");
}

TEST(LoadSubsystemFile, DirectoryIsRefused) {
  auto r = load_subsystem_file(kData, registry());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, kData + ": is a directory, not a subsystem file (only regular files are read)");
}

}  // namespace
}  // namespace chimera
