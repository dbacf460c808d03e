// Switches across processes (issue 15, item 4): Figure 4's loop in the main process, its
// trajectory generator either in the main process too or in a module process, the two
// configurations switched back and forth. Each switch commits at one instant for both processes:
// the leaving generator is off before the joining one turns on, and both ends of the loop go on.

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/plugins.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"
#include "run_chimera.hpp"
#include "started_subsystem.hpp"

namespace chimera {
namespace {

using test::TempDir;

constexpr std::int64_t kStepNs = 20'000'000;
constexpr int kMaxSteps = 1500;

constexpr const char* kFile =
    "subsystem: process_switch\n"
    "scheduler: rm\n"
    "tasks:\n"
    "  - {name: traj_here, module: joint_traj_gen, period: 2ms, criticality: soft}\n"
    "  - {name: traj_there, module: joint_traj_gen, period: 2ms, criticality: soft, process: planner}\n"
    "  - {name: pid, module: pid_joint, period: 2ms, criticality: soft}\n"
    "  - {name: robot, module: robot_torque, period: 2ms, criticality: soft}\n"
    "configurations:\n"
    "  here: [traj_here, pid, robot]\n"
    "  there: [traj_there, pid, robot]\n"
    "start: here\n";

const TaskSnapshot& task_of(const std::vector<TaskSnapshot>& all, const std::string& name) {
  const auto it = std::find_if(all.begin(), all.end(), [&](const TaskSnapshot& t) { return t.name == name; });
  EXPECT_NE(it, all.end()) << name;
  return *it;
}

TEST(ProcessSwitch, BackAndForthBetweenTheMainProcessAndAModuleProcess) {
  TempDir dir;
  const std::string path = dir.file("process_switch.yaml");
  test::write_text(path, kFile);
  const auto started = test::started_subsystem(path);  // a file without plugins: none loaded
  ASSERT_NE(started, nullptr);
  Subsystem& s = *started;
  // Not in the start configuration: the first switch creates it, and starts its process.
  ASSERT_EQ(task_of(s.snapshot(), "traj_there").state, TaskState::kNotCreated);

  for (int round = 0; round < 6; ++round) {
    const bool to_there = round % 2 == 0;
    const std::string joining = to_there ? "traj_there" : "traj_here";
    const std::string leaving = to_there ? "traj_here" : "traj_there";
    auto switched = s.switch_to(to_there ? "there" : "here");
    ASSERT_TRUE(switched.ok()) << "round " << round << ": " << switched.error().message;
    const auto after = s.snapshot();
    EXPECT_EQ(task_of(after, joining).state, TaskState::kOn) << "round " << round;
    EXPECT_EQ(task_of(after, leaving).state, TaskState::kOff) << "round " << round;
    // The joining generator cycles (in whichever process it runs) and the loop runs on.
    bool ran = false;
    for (int i = 0; i < kMaxSteps && !ran; ++i) {
      s.run_for(kStepNs);
      const auto now = s.snapshot();
      ran = task_of(now, joining).stats.cycles >= task_of(after, joining).stats.cycles + 20 &&
            task_of(now, "pid").stats.cycles >= task_of(after, "pid").stats.cycles + 20;
    }
    EXPECT_TRUE(ran) << "round " << round;
    EXPECT_EQ(task_of(s.snapshot(), leaving).stats.cycles, task_of(after, leaving).stats.cycles)
        << "round " << round << ": the leaving generator ran on after the switch";
  }
  EXPECT_EQ(s.configuration(), "here");
  for (const auto& t : s.snapshot()) EXPECT_NE(t.state, TaskState::kError) << t.name << ": " << t.last_error;
  s.stop();
}

// A module in a module process asks for switches as one in the main process does: its request
// reaches the main process's service thread through the task block, which switches. Two askers
// in the planner process take turns: each, once on, asks for the other's configuration.
TEST(ProcessSwitch, AModuleInAModuleProcessAsksForSwitches) {
  TempDir dir;
  const std::string path = dir.file("asked_switch.yaml");
  test::write_text(path,
                   "subsystem: asked_switch\n"
                   "plugins: [" FAULTY_PLUGIN
                   "]\n"
                   "tasks:\n"
                   "  - {name: traj, module: joint_traj_gen, period: 2ms, criticality: soft}\n"
                   "  - {name: pid, module: pid_joint, period: 2ms, criticality: soft}\n"
                   "  - {name: robot, module: robot_torque, period: 2ms, criticality: soft}\n"
                   "  - {name: to_second, module: asks_for_switch, period: 2ms, criticality: soft, process: planner,"
                   " params: {to: second, after: 20}}\n"
                   "  - {name: to_first, module: asks_for_switch, period: 2ms, criticality: soft, process: planner,"
                   " params: {to: first, after: 20}}\n"
                   "configurations:\n"
                   "  first: [traj, pid, robot, to_second]\n"
                   "  second: [traj, pid, robot, to_first]\n"
                   "requests:\n"
                   "  - {from: first, to: second, by: to_second}\n"
                   "  - {from: second, to: first, by: to_first}\n");
  const auto started = test::started_subsystem(path);
  ASSERT_NE(started, nullptr);
  Subsystem& s = *started;
  for (int i = 0; i < kMaxSteps && s.switches().size() < 4; ++i) s.run_for(kStepNs);
  const auto switches = s.switches();
  ASSERT_GE(switches.size(), 4U) << "the askers' requests did not reach the main process";
  for (std::size_t i = 0; i < 4; ++i) {
    const bool to_second = i % 2 == 0;
    EXPECT_EQ(switches[i].to, to_second ? "second" : "first") << i;
    EXPECT_EQ(switches[i].cause, to_second ? "requested by to_second" : "requested by to_first") << i;
  }
  for (const auto& t : s.snapshot()) EXPECT_NE(t.state, TaskState::kError) << t.name << ": " << t.last_error;
  s.stop();
}

}  // namespace
}  // namespace chimera
