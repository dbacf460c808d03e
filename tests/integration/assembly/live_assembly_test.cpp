// The live assembly through the one command API (what the shell and the network send): tasks
// added to a running subsystem, configurations defined, verified with the set difference named,
// switched to without a lost cycle, tasks removed, and the whole saved as a file that verifies
// and starts the same subsystem. Every refusal changes nothing. Virtual clock: deterministic.

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/spec_writer.hpp"
#include "chimera/control/control.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

// Figure 4, and a spare task that no configuration uses.
constexpr const char* kFig4 = R"(subsystem: assembly_test
tasks:
  - {name: traj, module: joint_traj_gen, period: 1ms, criticality: soft}
  - {name: pid, module: pid_joint, period: 1ms}
  - {name: robot, module: robot_torque, period: 1ms}
  - {name: load, module: cpu_load, period: 10ms, criticality: soft}
  - {name: spare, module: cpu_load, period: 20ms, criticality: soft}
configurations:
  pid_control: [traj, pid, robot]
start: pid_control
)";

std::string unique_suffix() {
  static std::atomic<int> counter{0};
  return "_asm_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class LiveAssemblyTest : public ::testing::Test {
 protected:
  void start(const SubsystemSpec& spec) {
    RunOptions options;
    options.clock = ClockKind::kVirtual;
    options.shm_suffix = unique_suffix();
    suffix_ = options.shm_suffix;
    auto created = Subsystem::create(spec, Registry::global(), options);
    ASSERT_TRUE(created.ok()) << created.error().message;
    subsystem_ = std::move(*created);
    auto started = subsystem_->start();
    ASSERT_TRUE(started.ok()) << started.error().message;
    control_ = std::make_unique<Control>(*subsystem_);
  }
  void start_text(const std::string& yaml) {
    auto spec = load_subsystem_text(yaml, "assembly_test.yaml", Registry::global());
    ASSERT_TRUE(spec.ok()) << spec.error().message;
    start(*spec);
  }
  void TearDown() override {
    control_.reset();
    if (subsystem_) subsystem_->stop();
  }

  Reply run(std::string_view line) { return control_->execute_line(line); }
  Reply ok(std::string_view line) {
    Reply r = run(line);
    EXPECT_TRUE(r.ok) << line << ": " << r.text;
    return r;
  }
  // Refused, with `why` in its one line, and nothing changed: the file and every task as before.
  void refused(std::string_view line, const std::string& why) {
    const std::string before_file = write_subsystem_yaml(subsystem_->spec());
    const std::string before_status = states();
    const Reply r = run(line);
    EXPECT_FALSE(r.ok) << line << ": " << r.text;
    EXPECT_TRUE(contains(r.text, why)) << line << ": " << r.text;
    EXPECT_EQ(std::count(r.text.begin(), r.text.end(), '\n'), 1) << r.text;
    EXPECT_EQ(write_subsystem_yaml(subsystem_->spec()), before_file) << line;
    EXPECT_EQ(states(), before_status) << line;
  }
  std::string states() const {
    std::string out;
    for (const auto& t : subsystem_->snapshot()) out += t.name + ":" + std::string(state_name(t.state)) + " ";
    return out;
  }
  TaskSnapshot task(const std::string& name) const {
    for (const auto& t : subsystem_->snapshot())
      if (t.name == name) return t;
    ADD_FAILURE() << "no task " << name;
    return {};
  }
  void run_for(std::int64_t ns) { subsystem_->run_for(ns); }

  std::unique_ptr<Subsystem> subsystem_;
  std::unique_ptr<Control> control_;
  std::string suffix_;  // of the subsystem's shared memory
};

TEST_F(LiveAssemblyTest, VerifyNamesTheSetDifferenceAndNeverSwitches) {
  start_text(kFig4);
  run_for(20 * kMs);
  const Reply defined = ok("define open_loop traj robot");
  EXPECT_TRUE(contains(defined.text, "not legal: tau_r has no producer (read by robot)")) << defined.text;
  const Reply verified = ok("verify open_loop");
  EXPECT_TRUE(contains(verified.text, "configuration 'open_loop' is not legal: tau_r has no producer"))
      << verified.text;
  EXPECT_TRUE(contains(verified.text, "rule 2: tau_r")) << verified.text;
  EXPECT_EQ(subsystem_->configuration(), "pid_control");
  // Two producers of one variable (eq. 1): the robot interfaces both publish theta_m.
  ok("define twice traj pid robot spare");
  auto violations = subsystem_->verify_configuration("twice");
  ASSERT_TRUE(violations.ok());
  EXPECT_TRUE(violations->empty());  // cpu_load produces nothing: still legal
  ok("define bad pid robot");
  const Reply missing = ok("verify bad");
  EXPECT_TRUE(contains(missing.text, "theta_d has no producer (read by pid)")) << missing.text;
  EXPECT_TRUE(contains(missing.text, "dtheta_d has no producer (read by pid)")) << missing.text;
  EXPECT_TRUE(ok("verify pid_control").text == "configuration 'pid_control' is legal\n");
  refused("switch bad", "theta_d");
  refused("verify nosuch", "no configuration named nosuch");
  EXPECT_EQ(subsystem_->configuration(), "pid_control");
}

TEST_F(LiveAssemblyTest, ADefinedConfigurationIsSwitchedToWithoutALostCycle) {
  start_text(kFig4);
  run_for(50 * kMs);
  ok("define loaded traj pid robot load");
  const auto before = task("robot");
  const std::int64_t t0 = subsystem_->now_ns();
  ok("switch loaded");
  run_for(100 * kMs);
  const std::int64_t t1 = subsystem_->now_ns();
  const auto after = task("robot");
  EXPECT_EQ(subsystem_->configuration(), "loaded");
  EXPECT_EQ(task("load").state, TaskState::kOn);
  // Every 1 ms release of the robot between the two instants ran, and none was late.
  EXPECT_EQ(after.stats.cycles - before.stats.cycles, static_cast<std::uint64_t>(t1 / kMs - t0 / kMs));
  EXPECT_EQ(after.stats.missed, 0U);
  EXPECT_EQ(subsystem_->switches().size(), 1U);
}

TEST_F(LiveAssemblyTest, DefineRefusesWhatCannotBeAConfiguration) {
  start_text(kFig4);
  refused("define pid_control traj", "is on");
  refused("define x traj nosuch", "no task named 'nosuch'");
  refused("define x traj traj", "listed twice");
  refused("define 9x traj", "not a valid configuration name");
  ok("define x traj");
  ok("define x traj pid");  // one that is not on may be defined anew
  EXPECT_EQ(subsystem_->spec().find_configuration("x")->tasks, (std::vector<std::string>{"traj", "pid"}));
}

TEST_F(LiveAssemblyTest, RemoveOnlyWhatNoConfigurationUses) {
  start_text(kFig4);
  ok("define loaded traj pid robot load");
  refused("remove pid", "in configurations pid_control, loaded");
  refused("remove load", "in configuration loaded");
  refused("remove nosuch", "no task named 'nosuch'");
  ok("spawn spare");
  ok("on spare");
  refused("remove spare", "is ON");
  ok("off spare");
  ok("remove spare");  // OFF: killed, then removed
  EXPECT_FALSE(contains(states(), "spare"));
  refused("on spare", "unknown task 'spare'");
  refused("define y spare", "no task named 'spare'");
  EXPECT_FALSE(contains(ok("save").text, "spare"));
}

TEST_F(LiveAssemblyTest, TasksAreAddedToAnEmptySubsystemAndRun) {
  SubsystemSpec empty;
  empty.name = "assembly_empty";
  empty.file = "(test)";
  empty.configurations.push_back(ConfigurationSpec{"empty", {}, {}});
  empty.start = "empty";
  start(empty);
  run_for(30 * kMs);
  // The robot interface first: its out-const ndof sizes the other tasks' ports.
  refused("add {name: traj, module: joint_traj_gen, period: 1ms, criticality: soft}", "size of");
  const Reply robot = ok("add {name: robot, module: robot_torque, period: 1ms}");
  EXPECT_EQ(robot.text, "robot: NOT-CREATED (added)\n");
  ok("add {name: traj, module: joint_traj_gen, period: 1ms, criticality: soft}");
  ok("add {name: control, module: pid_joint, period: 1ms, rename: {tau_r: tau_pid}, params: {kp: [400, 400, 400, 50, "
     "50, 50]}}");
  EXPECT_EQ(subsystem_->now_ns(), 30 * kMs);  // the clock went on through the adds
  ok("define fig4 traj control robot");
  EXPECT_TRUE(contains(ok("verify fig4").text, "tau_r has no producer (read by robot)"));
  refused("switch fig4", "tau_r");
  ok("add {name: limit, module: torque_limit, period: 1ms, rename: {tau_in: tau_pid, tau_out: tau_r}}");
  ok("define fig4 traj control limit robot");
  EXPECT_EQ(ok("verify fig4").text, "configuration 'fig4' is legal\n");
  ok("switch fig4");
  run_for(200 * kMs);
  EXPECT_GE(task("robot").stats.cycles, 199U);
  EXPECT_EQ(task("control").state, TaskState::kOn);
  // The arm follows the trajectory: the control loop is closed through the table.
  auto theta_m = subsystem_->get("theta_m");
  auto theta_d = subsystem_->get("theta_d");
  ASSERT_TRUE(theta_m.ok() && theta_d.ok());
  for (std::size_t j = 0; j < theta_m->size(); ++j) EXPECT_NEAR((*theta_m)[j], (*theta_d)[j], 0.05) << j;
  // Added while tasks run: refused, nothing changed.
  refused("add {name: more, module: cpu_load, period: 10ms}", "task robot is ON");
}

TEST_F(LiveAssemblyTest, AddRefusesWhatTheFileWouldRefuse) {
  SubsystemSpec empty;
  empty.name = "assembly_refuse";
  empty.file = "(test)";
  empty.configurations.push_back(ConfigurationSpec{"empty", {}, {}});
  empty.start = "empty";
  start(empty);
  ok("add {name: a, module: cpu_load, period: 10ms}");
  refused("add {name: a, module: cpu_load, period: 10ms}", "task a is already defined");
  refused("add {name: b, module: nosuch, period: 10ms}", "nosuch");
  refused("add {name: b, module: cpu_load, period: 10 ms}", "period");
  refused("add {name: b, module: cpu_load, colour: red}", "colour");
  refused("add {name: b, module: cpu_load, params: {nosuch: 1}}", "unknown parameter");
  refused("add name: b", "in braces");
  refused("add {name: b, module: cpu_load}\nconfigurations: {}", "one line");
  EXPECT_EQ(subsystem_->spec().tasks.size(), 1U);
}

TEST_F(LiveAssemblyTest, SaveWritesAFileThatVerifiesAndStartsTheSameSubsystem) {
  start_text(kFig4);
  ok("define loaded traj pid robot load");
  ok("switch loaded");
  ok("remove spare");
  run_for(20 * kMs);
  const std::string path = ::testing::TempDir() + "/assembly_saved_" + std::to_string(::getpid()) + ".yaml";
  EXPECT_EQ(ok("save " + path).text, "saved to " + path + "\n");

  auto loaded = load_subsystem_file(path, Registry::global());
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_TRUE(verify_subsystem(resolve_subsystem(*loaded, Registry::global())).empty());
  EXPECT_EQ(loaded->start, "loaded");
  EXPECT_EQ(write_subsystem_yaml(*loaded), ok("save").text);  // a fixed point: nothing lost, nothing added

  RunOptions options;
  options.clock = ClockKind::kVirtual;
  options.shm_suffix = unique_suffix();
  auto again = Subsystem::create(*loaded, Registry::global(), options);
  ASSERT_TRUE(again.ok()) << again.error().message;
  ASSERT_TRUE((*again)->start().ok());
  const auto a = subsystem_->snapshot();
  const auto b = (*again)->snapshot();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].name, b[i].name);
    EXPECT_EQ(a[i].module, b[i].module);
    EXPECT_EQ(a[i].state, b[i].state) << a[i].name;
    EXPECT_EQ(a[i].period_ns, b[i].period_ns) << a[i].name;
  }
  EXPECT_EQ((*again)->configuration(), subsystem_->configuration());
  (*again)->stop();
  std::remove(path.c_str());

  ok("define open_loop traj robot");
  refused("save", "configuration 'open_loop' is not legal");
}

// Another subsystem for open: two tasks, and its start configuration runs both.
constexpr const char* kOther = R"(subsystem: other_test
tasks:
  - {name: fast, module: cpu_load, period: 2ms, criticality: soft}
  - {name: slow, module: cpu_load, period: 10ms, criticality: soft}
configurations:
  only_fast: [fast]
  both: [fast, slow]
start: both
)";

std::string written(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + std::to_string(::getpid()) + "_" + name;
  std::ofstream(path) << text;
  return path;
}

TEST_F(LiveAssemblyTest, OpenRunsAnotherFileInTheRunningSubsystem) {
  start_text(kFig4);
  run_for(50 * kMs);
  ok("define loaded traj pid robot load");
  ok("switch loaded");
  run_for(10 * kMs);
  const std::string other = written("other.yaml", kOther);
  const std::int64_t before = subsystem_->now_ns();
  const Reply opened = ok("open " + other);
  EXPECT_EQ(opened.text, "opened " + other + ": subsystem other_test, configuration 'both' on (fast: ON, slow: ON)\n");
  // The file's tasks and nothing of Figure 4's; the run's clock and its history of switches go on.
  EXPECT_EQ(states(), "fast:ON slow:ON ");
  EXPECT_EQ(subsystem_->spec().name, "other_test");
  EXPECT_EQ(subsystem_->configuration(), "both");
  EXPECT_EQ(subsystem_->now_ns(), before);
  EXPECT_EQ(subsystem_->switches().size(), 1U);
  EXPECT_FALSE(subsystem_->get("theta_m").ok());
  run_for(100 * kMs);
  EXPECT_EQ(task("fast").stats.cycles, 50U);  // every 2 ms release of 100 ms, on time
  EXPECT_EQ(task("slow").stats.cycles, 10U);
  EXPECT_EQ(task("fast").stats.missed, 0U);
  ok("switch only_fast");
  EXPECT_EQ(task("slow").state, TaskState::kOff);

  // And back to Figure 4 from its file: the arm follows the trajectory again.
  const Reply back = ok("open " + written("fig4.yaml", kFig4));
  EXPECT_TRUE(contains(back.text,
                       "subsystem assembly_test, configuration 'pid_control' on (traj: ON, pid: ON, robot: "
                       "ON, load: NOT-CREATED, spare: NOT-CREATED)"))
      << back.text;
  run_for(300 * kMs);
  EXPECT_EQ(task("robot").stats.cycles, 300U);
  auto theta_m = subsystem_->get("theta_m");
  auto theta_d = subsystem_->get("theta_d");
  ASSERT_TRUE(theta_m.ok() && theta_d.ok());
  for (std::size_t j = 0; j < theta_m->size(); ++j) EXPECT_NEAR((*theta_m)[j], (*theta_d)[j], 0.05) << j;
  EXPECT_EQ(subsystem_->switches().size(), 2U);
}

TEST_F(LiveAssemblyTest, OpenRefusesAFileThatCannotRunAndChangesNothing) {
  start_text(kFig4);
  run_for(20 * kMs);
  std::string bad_period(kOther);
  bad_period.replace(bad_period.find("period: 10ms"), 12, "period: 10 ms");
  const std::string path = written("bad_period.yaml", bad_period);
  refused("open " + path, path + ":4: tasks[1].period");
  refused("open " + written("illegal.yaml", std::string(kFig4).replace(std::string(kFig4).find("[traj, pid, robot]"),
                                                                       18, "[traj, robot]")),
          "configuration 'pid_control' is not legal: configuration 'pid_control': rule 2");
  refused("open " + written("broken.yaml", "subsystem: x\ntasks: [\n"), "broken.yaml");
  refused("open /nonexistent/chimera.yaml", "/nonexistent/chimera.yaml");
  refused("open " + written("unknown.yaml",
                            std::string(kOther).replace(std::string(kOther).find("cpu_load"), 8, "no_such_module")),
          "no_such_module");
  EXPECT_EQ(subsystem_->spec().name, "assembly_test");
  run_for(20 * kMs);
  EXPECT_EQ(task("robot").stats.cycles, 40U);  // every cycle of the 40 ms ran through the refusals
}

TEST_F(LiveAssemblyTest, AnOpenTheMachineRefusesPutsTheSubsystemBackRunning) {
  start_text(kFig4);
  run_for(20 * kMs);
  // The file's subsystem already runs on this machine (its shared memory is taken): found only
  // once the tasks were killed, so the subsystem before is made and started again.
  auto spec = load_subsystem_text(kOther, "other.yaml", Registry::global());
  ASSERT_TRUE(spec.ok());
  RunOptions options;
  options.clock = ClockKind::kVirtual;
  options.shm_suffix = suffix_;
  auto elsewhere = Subsystem::create(*spec, Registry::global(), options);
  ASSERT_TRUE(elsewhere.ok()) << elsewhere.error().message;
  const Reply r = run("open " + written("other.yaml", kOther));
  EXPECT_FALSE(r.ok) << r.text;
  EXPECT_TRUE(contains(r.text, "subsystem 'other_test" + suffix_ + "' is already running")) << r.text;
  EXPECT_TRUE(contains(r.text, "the subsystem before runs again, configuration 'pid_control' started anew")) << r.text;
  EXPECT_EQ(subsystem_->spec().name, "assembly_test");
  EXPECT_EQ(states(), "traj:ON pid:ON robot:ON load:NOT-CREATED spare:NOT-CREATED ");
  const std::uint64_t cycles = task("robot").stats.cycles;
  run_for(50 * kMs);
  EXPECT_EQ(task("robot").stats.cycles, cycles + 50);
  (*elsewhere)->stop();
}

}  // namespace
}  // namespace chimera
