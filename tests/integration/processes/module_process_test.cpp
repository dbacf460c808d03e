// Module processes (issue 15, docs/processes.md): Figure 4's loop in the main process beside a
// module that writes through a null pointer and one that calls abort(), each in a process of its
// own. The loop keeps cycling, the faulty tasks are ERROR with the signal that ended their
// process, the illegal-configuration flag is up, and clear + on brings them back in a new process.

#include <sys/stat.h>
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

namespace chimera {
namespace {

using test::TempDir;

// Long enough for a loaded machine to start the workers and reach the faults; the tests wait for
// what must happen, never for an amount of time to pass.
constexpr std::int64_t kStepNs = 20'000'000;
constexpr int kMaxSteps = 1500;

std::string file_text(const TempDir& dir) {
  return "subsystem: fig4_processes\n"
         "plugins: [" FAULTY_PLUGIN "]\n"
         "scheduler: rm\n"
         "tasks:\n"
         "  - {name: traj, module: joint_traj_gen, period: 1ms, criticality: soft}\n"
         "  - {name: pid, module: pid_joint, period: 1ms, criticality: soft}\n"
         "  - {name: robot, module: robot_torque, period: 1ms, criticality: soft}\n"
         "  - name: segv\n"
         "    module: segfault_in_cycle\n"
         "    period: 2ms\n"
         "    criticality: soft\n"
         "    process: faulty\n"
         "    params: {after: 25, once_file: " + dir.file("segv.once") + "}\n"
         "  - name: aborts\n"
         "    module: abort_in_cycle\n"
         "    period: 2ms\n"
         "    criticality: soft\n"
         "    process: aborting\n"
         "    rename: {faulty_count: abort_count}\n"
         "    params: {after: 25, once_file: " + dir.file("abort.once") + "}\n";
}

const TaskSnapshot& task_of(const std::vector<TaskSnapshot>& all, const std::string& name) {
  const auto it = std::find_if(all.begin(), all.end(), [&](const TaskSnapshot& t) { return t.name == name; });
  EXPECT_NE(it, all.end()) << name;
  return *it;
}

// Runs until `done` holds for the snapshot, or gives up after kMaxSteps.
template <class Done>
bool run_until(Subsystem& s, Done done) {
  for (int i = 0; i < kMaxSteps; ++i) {
    if (done(s.snapshot())) return true;
    s.run_for(kStepNs);
  }
  return false;
}

class ModuleProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string path = dir_.file("fig4_processes.yaml");
    test::write_text(path, file_text(dir_));
    auto plugins = load_file_plugins(path);
    ASSERT_TRUE(plugins.ok()) << plugins.error().message;
    auto spec = load_subsystem_file(path, Registry::global());
    ASSERT_TRUE(spec.ok()) << spec.error().message;
    RunOptions options;
    options.realtime_priorities = false;  // the test runs anywhere; priorities are not its subject
    options.shm_suffix = "_" + std::to_string(::getpid());
    options.worker_program = CHIMERA_BIN;
    auto made = Subsystem::create(*spec, Registry::global(), options);
    ASSERT_TRUE(made.ok()) << made.error().message;
    subsystem_ = std::move(*made);
    ASSERT_TRUE(subsystem_->start().ok());
  }

  TempDir dir_;
  std::unique_ptr<Subsystem> subsystem_;
};

TEST_F(ModuleProcessTest, CrashesStopOnlyTheirTasksAndClearBringsThemBack) {
  Subsystem& s = *subsystem_;
  const auto both_in_error = [](const std::vector<TaskSnapshot>& all) {
    return task_of(all, "segv").state == TaskState::kError && task_of(all, "aborts").state == TaskState::kError;
  };
  ASSERT_TRUE(run_until(s, both_in_error));
  const auto at_faults = s.snapshot();
  EXPECT_NE(task_of(at_faults, "segv").last_error.find("its process faulty died (killed by SIGSEGV"),
            std::string::npos)
      << task_of(at_faults, "segv").last_error;
  EXPECT_NE(task_of(at_faults, "aborts").last_error.find("its process aborting died (killed by SIGABRT"),
            std::string::npos)
      << task_of(at_faults, "aborts").last_error;
  EXPECT_TRUE(s.illegal_configuration());
  // The faulty tasks ran in other processes: their cycles were counted where the main process reads them.
  EXPECT_GE(task_of(at_faults, "segv").stats.cycles, 24U);

  // Figure 4's loop keeps cycling, ON, after both deaths.
  const auto grew = [&](const std::vector<TaskSnapshot>& now) {
    for (const char* name : {"traj", "pid", "robot"})
      if (task_of(now, name).stats.cycles <= task_of(at_faults, name).stats.cycles + 50) return false;
    return true;
  };
  ASSERT_TRUE(run_until(s, grew));
  for (const auto& t : s.snapshot()) {
    if (t.name == "traj" || t.name == "pid" || t.name == "robot") {
      EXPECT_EQ(t.state, TaskState::kOn) << t.name;
    }
  }

  // clear starts each process again: its task is OFF, then on as usual, and cycles in the new process.
  for (const char* name : {"segv", "aborts"}) {
    auto cleared = s.signal(name, Signal::kClear);
    ASSERT_TRUE(cleared.ok()) << cleared.error().message;
    EXPECT_EQ(task_of(s.snapshot(), name).state, TaskState::kOff);
    auto on = s.signal(name, Signal::kOn);
    ASSERT_TRUE(on.ok()) << on.error().message;
  }
  const auto before = s.snapshot();
  const auto back = [&](const std::vector<TaskSnapshot>& now) {
    for (const char* name : {"segv", "aborts"})
      if (task_of(now, name).state != TaskState::kOn ||
          task_of(now, name).stats.cycles <= task_of(before, name).stats.cycles + 30)
        return false;
    return true;
  };
  EXPECT_TRUE(run_until(s, back));
  auto value = s.get("faulty_count");
  ASSERT_TRUE(value.ok()) << value.error().message;
  EXPECT_GT((*value)[0], 25.0);  // the new process's cycles, past the one that crashed the first
  s.stop();
  EXPECT_EQ(task_of(s.snapshot(), "segv").state, TaskState::kNotCreated);
}

TEST_F(ModuleProcessTest, TasksOfADeadProcessAreKilledByStop) {
  Subsystem& s = *subsystem_;
  ASSERT_TRUE(run_until(s, [](const auto& all) { return task_of(all, "segv").state == TaskState::kError; }));
  // on is refused, saying why and what to do.
  auto on = s.signal("segv", Signal::kOn);
  ASSERT_FALSE(on.ok());
  s.stop();
  for (const auto& t : s.snapshot()) EXPECT_EQ(t.state, TaskState::kNotCreated) << t.name;
}

}  // namespace
}  // namespace chimera
