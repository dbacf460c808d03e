// Module processes (issue 15, docs/processes.md): Figure 4's loop in the main process beside a
// module that writes through a null pointer, one that calls abort(), one that calls exit(3) and
// one that never returns from cycle(), each in a process of its own. The loop keeps cycling, the
// faulty tasks are ERROR with what ended their process (the stuck one's killed by the supervisor
// for its heartbeat), the illegal-configuration flag is up, and clear + on brings them back in a
// new process.

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
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

// Long enough for a loaded machine to start the workers and reach the faults; the tests wait for
// what must happen, never for an amount of time to pass.
constexpr std::int64_t kStepNs = 20'000'000;
constexpr int kMaxSteps = 1500;

std::string file_text(const TempDir& dir) {
  return "subsystem: fig4_processes\n"
         "plugins: [" FAULTY_PLUGIN
         "]\n"
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
         "    params: {after: 25, once_file: " +
         dir.file("segv.once") +
         "}\n"
         "  - name: aborts\n"
         "    module: abort_in_cycle\n"
         "    period: 2ms\n"
         "    criticality: soft\n"
         "    process: aborting\n"
         "    rename: {faulty_count: abort_count}\n"
         "    params: {after: 25, once_file: " +
         dir.file("abort.once") +
         "}\n"
         "  - name: exits\n"
         "    module: exit_in_cycle\n"
         "    period: 2ms\n"
         "    criticality: soft\n"
         "    process: exiting\n"
         "    rename: {faulty_count: exit_count}\n"
         "    params: {after: 25, once_file: " +
         dir.file("exit.once") +
         "}\n"
         "  - name: spin\n"
         "    module: loop_in_cycle\n"
         "    period: 2ms\n"
         "    criticality: soft\n"
         "    process: spinning\n"
         "    rename: {faulty_count: spin_count}\n"
         "    params: {after: 25, once_file: " +
         dir.file("spin.once") + "}\n";
}

constexpr const char* kFaulty[] = {"segv", "aborts", "exits", "spin"};

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

// A sanitizer's own SIGSEGV handler would report and exit with its code: in a sanitized build
// the workers still die of the signal, as in a plain one. Read by the workers only (this process
// read its options at start).
void let_workers_die_of_segv() {
  for (const char* var : {"ASAN_OPTIONS", "TSAN_OPTIONS"}) {
    const char* now = std::getenv(var);  // NOLINT(concurrency-mt-unsafe): before any worker or thread
    if (now != nullptr && std::strstr(now, "handle_segv=0") != nullptr) continue;
    const std::string value =
        (now != nullptr && *now != '\0' ? std::string(now) + ":" : std::string()) + "handle_segv=0";
    ::setenv(var, value.c_str(), 1);  // NOLINT(concurrency-mt-unsafe): as above
  }
}

class ModuleProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    let_workers_die_of_segv();
    const std::string path = dir_.file("fig4_processes.yaml");
    test::write_text(path, file_text(dir_));
    RunOptions options;
    adjust(options);
    subsystem_ = test::started_subsystem(path, options);
    ASSERT_NE(subsystem_, nullptr);
  }

  virtual void adjust(RunOptions& /*options*/) {}

  TempDir dir_;
  std::unique_ptr<Subsystem> subsystem_;
};

// The same subsystem with the flight recorder on, its dumps below the test's directory.
class ModuleProcessRecorderTest : public ModuleProcessTest {
 protected:
  void adjust(RunOptions& options) override {
    options.record_seconds = 2;
    options.error_dump_dir = dumps();
  }
  [[nodiscard]] std::string dumps() const { return dir_.file("dumps"); }
};

// One column of a CSV file with a header, as text, by its header's name ("" cells for a short row).
std::vector<std::string> csv_column(const std::string& path, const std::string& name) {
  std::istringstream in(test::read_text(path));
  std::string line;
  std::getline(in, line);
  const auto cells = [](const std::string& row) {
    std::vector<std::string> out;
    std::stringstream fields(row);
    for (std::string cell; std::getline(fields, cell, ',');) out.push_back(cell);
    return out;
  };
  const auto header = cells(line);
  const auto at = std::find(header.begin(), header.end(), name);
  EXPECT_NE(at, header.end()) << path << " has no column " << name;
  if (at == header.end()) return {};
  const auto k = static_cast<std::size_t>(at - header.begin());
  std::vector<std::string> column;
  while (std::getline(in, line)) {
    const auto row = cells(line);
    column.push_back(k < row.size() ? row[k] : std::string());
  }
  return column;
}

TEST_F(ModuleProcessTest, CrashesStopOnlyTheirTasksAndClearBringsThemBack) {
  Subsystem& s = *subsystem_;
  const auto all_in_error = [](const std::vector<TaskSnapshot>& all) {
    for (const char* name : kFaulty)
      if (task_of(all, name).state != TaskState::kError) return false;
    return true;
  };
  ASSERT_TRUE(run_until(s, all_in_error));
  const auto at_faults = s.snapshot();
  const auto says = [&](const char* task, const std::string& reason) {
    EXPECT_NE(task_of(at_faults, task).last_error.find(reason), std::string::npos)
        << task << ": " << task_of(at_faults, task).last_error;
  };
  says("segv", "its process faulty died (killed by SIGSEGV");
  says("aborts", "its process aborting died (killed by SIGABRT");
  says("exits", "its process exiting died (exited with code 3)");
  says("spin", "its process spinning died (killed by the supervisor: spin stuck in cycle() for ");
  EXPECT_TRUE(s.illegal_configuration());
  // The faulty tasks ran in other processes: their cycles were counted where the main process reads them.
  for (const char* name : kFaulty) EXPECT_GE(task_of(at_faults, name).stats.cycles, 24U) << name;

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
  for (const char* name : kFaulty) {
    auto cleared = s.signal(name, Signal::kClear);
    ASSERT_TRUE(cleared.ok()) << cleared.error().message;
    EXPECT_EQ(task_of(s.snapshot(), name).state, TaskState::kOff);
    auto on = s.signal(name, Signal::kOn);
    ASSERT_TRUE(on.ok()) << on.error().message;
  }
  EXPECT_FALSE(s.illegal_configuration()) << "every hold given back with the last clear";
  const auto before = s.snapshot();
  const auto back = [&](const std::vector<TaskSnapshot>& now) {
    for (const char* name : kFaulty)
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

// A module process's tasks write into the flight recorder's rings as the main process's do: the
// dumps hold what the segfaulting task wrote, each of its values up to the last before its death,
// and each of its cycles, beside Figure 4's in the main process.
TEST_F(ModuleProcessRecorderTest, TheRecorderHoldsWhatAModuleProcessWroteUntilItDied) {
  Subsystem& s = *subsystem_;
  ASSERT_TRUE(run_until(s, [](const auto& all) { return task_of(all, "segv").state == TaskState::kError; }));
  const std::string dump = dir_.file("operator-dump");
  auto written = s.dump(dump, "the test");
  ASSERT_TRUE(written.ok()) << written.error().message;

  // faulty_count is 0 as init and on publish it, then the cycle's number: 1, 2, ... up to 24, the
  // last cycle that returned (the 25th wrote through a null pointer before its outputs went out).
  // Rows of other variables' instants repeat a value; none is missing, none is past 24.
  std::vector<double> counts;
  for (const auto& cell : csv_column(dump + "/variables.csv", "faulty_count[0]")) {
    if (cell == "nan") continue;
    const double v = std::stod(cell);
    if (counts.empty() || v != counts.back()) counts.push_back(v);
  }
  std::string seen;
  for (const double v : counts) seen += std::to_string(static_cast<int>(v)) + " ";
  ASSERT_EQ(counts.size(), 25U) << "the values the worker's task wrote before its process died: " << seen;
  for (std::size_t k = 0; k < counts.size(); ++k) EXPECT_EQ(counts[k], static_cast<double>(k)) << seen;

  // timing.csv: a row for each of segv's 24 cycles that returned (the 25th never ended; a row of
  // releases skipped, as a worker's late start may make, is not a cycle), and Figure 4's pid's
  // rows beside them.
  const auto task = csv_column(dump + "/timing.csv", "task");
  const auto skipped = csv_column(dump + "/timing.csv", "skipped");
  ASSERT_EQ(task.size(), skipped.size());
  std::size_t segv_cycles = 0;
  std::size_t pid_rows = 0;
  for (std::size_t r = 0; r < task.size(); ++r) {
    segv_cycles += task[r] == "segv" && skipped[r] == "0" ? 1 : 0;
    pid_rows += task[r] == "pid" ? 1 : 0;
  }
  EXPECT_EQ(segv_cycles, 24U);
  EXPECT_GT(pid_rows, 24U);

  // The dump that the ERROR made by itself names the task.
  s.run_for(kStepNs);
  bool named = false;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dumps(), ec))
    named = named || test::read_text(entry.path().string() + "/summary.txt").find("segv") != std::string::npos;
  EXPECT_TRUE(named) << "no dump below " << dumps() << " names segv";
}

// The overrun watch covers a module process's tasks: a hard task there whose cycle does not return
// is reported once past its deadline and holds the illegal-configuration flag while it runs over
// (the robot holds), until the supervisor kills its process for the stuck cycle (ERROR). The
// death takes the overrun with it: once cleared and on again in a new process, no hold is left.
TEST(ModuleProcessOverrun, AHardTaskOverdueInAModuleProcessHoldsTheFlagUntilItsProcessEnds) {
  TempDir dir;
  const std::string path = dir.file("overdue.yaml");
  test::write_text(path,
                   "subsystem: overdue\n"
                   "plugins: [" FAULTY_PLUGIN
                   "]\n"
                   "tasks:\n"
                   "  - {name: tick, module: segfault_in_cycle, period: 2ms, criticality: soft,"
                   " params: {after: 1000000000}}\n"
                   "  - name: late\n"
                   "    module: loop_in_cycle\n"
                   "    period: 100ms\n"
                   "    criticality: hard\n"
                   "    process: slow\n"
                   "    rename: {faulty_count: late_count}\n"
                   "    params: {after: 3, once_file: " +
                       dir.file("late.once") + "}\n");
  const auto started = test::started_subsystem(path);
  ASSERT_NE(started, nullptr);
  Subsystem& s = *started;

  // Stuck from its 3rd cycle (released at 0.2 s): reported a watch tick past its deadline, while
  // its process still runs (the supervisor's bound is ten periods).
  std::string overdue;
  bool held_while_overdue = false;
  for (int i = 0; i < kMaxSteps && overdue.empty(); ++i) {
    s.run_for(kStepNs);
    for (const Event& e : s.drain_events())
      if (e.task == "late" && e.text.find("still running") != std::string::npos) overdue = e.text;
    if (!overdue.empty())
      held_while_overdue = s.illegal_configuration() && task_of(s.snapshot(), "late").state == TaskState::kOn;
  }
  ASSERT_FALSE(overdue.empty()) << "the main process's watch never saw the module process's job run over";
  EXPECT_NE(overdue.find("The illegal-configuration flag is up until it ends"), std::string::npos) << overdue;
  EXPECT_TRUE(held_while_overdue) << "the flag was not up while the hard job ran over, its process alive";

  ASSERT_TRUE(run_until(s, [](const auto& all) { return task_of(all, "late").state == TaskState::kError; }));
  EXPECT_NE(task_of(s.snapshot(), "late").last_error.find("killed by the supervisor: late stuck in cycle()"),
            std::string::npos)
      << task_of(s.snapshot(), "late").last_error;
  ASSERT_TRUE(s.signal("late", Signal::kClear).ok());
  ASSERT_TRUE(s.signal("late", Signal::kOn).ok());
  const auto cycled = [](const std::vector<TaskSnapshot>& all) { return task_of(all, "late").stats.cycles >= 5; };
  ASSERT_TRUE(run_until(s, cycled));
  EXPECT_FALSE(s.illegal_configuration()) << "a hold outlived the job that died with its process";
  s.stop();
}

// Aperiodic tasks are woken by their producers whatever process each is in: a ticker of the main
// process wakes a counter in a module process, and a ticker there wakes a counter of the main
// process. Each counter runs about a cycle per tick (an update seen late may serve two).
TEST(ModuleProcessTriggers, AnAperiodicTaskIsWokenByAProducerInAnotherProcess) {
  TempDir dir;
  const std::string path = dir.file("triggers.yaml");
  test::write_text(path,
                   "subsystem: triggers\n"
                   "plugins: [" FAULTY_PLUGIN
                   "]\n"
                   "tasks:\n"
                   "  - {name: tick_main, module: segfault_in_cycle, period: 5ms, criticality: soft,"
                   " params: {after: 1000000000}}\n"
                   "  - {name: count_side, module: counts_updates, criticality: soft, process: side,"
                   " rename: {x: faulty_count, updates: side_updates}}\n"
                   "  - {name: tick_side, module: exit_in_cycle, period: 5ms, criticality: soft, process: side,"
                   " rename: {faulty_count: side_count}, params: {after: 1000000000}}\n"
                   "  - {name: count_main, module: counts_updates, criticality: soft,"
                   " rename: {x: side_count, updates: main_updates}}\n");
  const auto started = test::started_subsystem(path);
  ASSERT_NE(started, nullptr);
  Subsystem& s = *started;
  const auto counted = [](const std::vector<TaskSnapshot>& all) {
    return task_of(all, "count_side").stats.cycles >= 40 && task_of(all, "count_main").stats.cycles >= 40;
  };
  EXPECT_TRUE(run_until(s, counted)) << "count_side ran " << task_of(s.snapshot(), "count_side").stats.cycles
                                     << " cycles, count_main " << task_of(s.snapshot(), "count_main").stats.cycles;
  // Woken by the ticks, not by anything else: never more cycles than ticks.
  const auto now = s.snapshot();
  EXPECT_LE(task_of(now, "count_side").stats.cycles, task_of(now, "tick_main").stats.cycles + 2);
  EXPECT_LE(task_of(now, "count_main").stats.cycles, task_of(now, "tick_side").stats.cycles + 2);
  s.stop();
}

// The same-rate rule across processes: a consumer of the main process reads its producer's value
// of the same release though the producer runs in a module process. A release that read another
// must be one the machine's load explains: the rule gave up waiting for it (an order timeout), the
// producer skipped or missed that release, or the consumer ran it so late that the producer had
// run the next (a miss of the consumer's). So mismatches never exceed those counts; without the
// rule across processes nearly every release of a consumer that runs first would read the
// release before.
// Runs `tasks` (a file's task list with a `stamp` producer and a `check` consumer) until check
// ran 300 releases, and checks the same-rate rule held between them as explained above.
void expect_same_release_stamps(const std::string& name, const std::string& tasks) {
  TempDir dir;
  const std::string path = dir.file(name + ".yaml");
  test::write_text(path, "subsystem: " + name + "\nplugins: [" FAULTY_PLUGIN "]\ntasks:\n" + tasks);
  const auto started = test::started_subsystem(path);
  ASSERT_NE(started, nullptr);
  Subsystem& s = *started;
  ASSERT_TRUE(run_until(s, [](const auto& all) { return task_of(all, "check").stats.cycles >= 300; }));
  // The count first, then the stats: a release between the two can only add to the excuses.
  auto mismatches = s.get("stamp_mismatches");
  ASSERT_TRUE(mismatches.ok()) << mismatches.error().message;
  const auto now = s.snapshot();
  s.stop();
  const auto& check = task_of(now, "check").stats;
  const auto& stamp = task_of(now, "stamp").stats;
  const double explained = static_cast<double>(check.order_timeouts + check.missed + stamp.missed);
  EXPECT_LE((*mismatches)[0], explained + 1.0)
      << "of " << check.cycles << " releases, " << (*mismatches)[0] << " read another release's stamp; "
      << check.order_timeouts << " gave up waiting, the consumer missed " << check.missed
      << " deadlines and the producer " << stamp.missed << " (" << stamp.skipped << " skipped)";
  EXPECT_LT(check.order_timeouts, check.cycles / 2) << "the rule gave up on most releases";
  EXPECT_LT(explained, static_cast<double>(check.cycles) / 2) << "too loaded a machine to tell";
}

TEST(ModuleProcessPrecedence, AConsumerReadsItsProducersValueOfTheSameReleaseAcrossProcesses) {
  expect_same_release_stamps("same_rate",
                             "  - {name: stamp, module: release_stamp, period: 5ms, criticality: soft, process: side}\n"
                             "  - {name: check, module: checks_stamp, period: 5ms, criticality: soft}\n");
}

// Figure 4 with the PID in its own process has this shape: the consumer shares a thread with a
// task placed before the producer (traj, pid, robot), so the producer's thread was made between
// the two. The consumer once took the number of that thread for its own, believed the producer
// ran on its thread and had had its turn, and never waited: every release read the one before,
// each counted as an order timeout.
TEST(ModuleProcessPrecedence, AConsumerWaitsForAProducerOfAnotherProcessPlacedBetweenItsThreadMates) {
  expect_same_release_stamps(
      "same_rate_between",
      "  - {name: head, module: release_stamp, period: 5ms, criticality: soft, cpu: 0, rename: {stamp: head_stamp}}\n"
      "  - {name: stamp, module: release_stamp, period: 5ms, criticality: soft, cpu: 0, process: side}\n"
      "  - {name: check, module: checks_stamp, period: 5ms, criticality: soft, cpu: 0}\n");
}

// The same shape in one process: the producer's thread is made between the consumer's thread-mates
// because it runs on the other CPU (the machines this runs on have two), after a task that takes
// 300 us, so that a consumer that does not wait reads the release before.
TEST(ModuleProcessPrecedence, AConsumerWaitsForAProducerOfAnotherCpuPlacedBetweenItsThreadMates) {
  expect_same_release_stamps(
      "same_rate_other_cpu",
      "  - {name: head, module: release_stamp, period: 5ms, criticality: soft, cpu: 0, rename: {stamp: head_stamp}}\n"
      "  - {name: slow, module: cpu_load, period: 5ms, criticality: soft, cpu: 1, params: {exec: 0.0003}}\n"
      "  - {name: stamp, module: release_stamp, period: 5ms, criticality: soft, cpu: 1}\n"
      "  - {name: check, module: checks_stamp, period: 5ms, criticality: soft, cpu: 0}\n");
}

// A stray pointer in a module process writes only where its own tasks write: the table's other
// variables' pages are read-only there. A module that writes over the whole table (each byte as
// it was) dies of SIGSEGV at the first page not its own, its task ERROR; Figure 4's loop beside it
// runs on. Where every page was writable it would write them all and live on.
TEST(ModuleProcessIsolation, AStrayWriteToAnotherWritersVariableFaultsInItsOwnProcess) {
  let_workers_die_of_segv();
  TempDir dir;
  const std::string path = dir.file("stray.yaml");
  test::write_text(path,
                   "subsystem: stray\n"
                   "plugins: [" FAULTY_PLUGIN
                   "]\n"
                   "tasks:\n"
                   "  - {name: traj, module: joint_traj_gen, period: 1ms, criticality: soft}\n"
                   "  - {name: pid, module: pid_joint, period: 1ms, criticality: soft}\n"
                   "  - {name: robot, module: robot_torque, period: 1ms, criticality: soft}\n"
                   "  - {name: stray, module: scribbles_on_the_table, period: 2ms, criticality: soft,"
                   " process: wild, params: {after: 25}}\n");
  const auto started = test::started_subsystem(path);
  ASSERT_NE(started, nullptr);
  Subsystem& s = *started;
  ASSERT_TRUE(run_until(s, [](const auto& all) { return task_of(all, "stray").state == TaskState::kError; }))
      << "the stray writes went through: every page of the table was writable in its process";
  const auto at_fault = s.snapshot();
  EXPECT_NE(task_of(at_fault, "stray").last_error.find("its process wild died (killed by SIGSEGV"), std::string::npos)
      << task_of(at_fault, "stray").last_error;
  const auto grew = [&](const std::vector<TaskSnapshot>& now) {
    for (const char* name : {"traj", "pid", "robot"})
      if (task_of(now, name).stats.cycles <= task_of(at_fault, name).stats.cycles + 100) return false;
    return true;
  };
  EXPECT_TRUE(run_until(s, grew));
  for (const char* name : {"traj", "pid", "robot"})
    EXPECT_EQ(task_of(s.snapshot(), name).state, TaskState::kOn) << name;
  auto ndof = s.get("ndof");
  ASSERT_TRUE(ndof.ok()) << ndof.error().message;
  EXPECT_EQ((*ndof)[0], 6.0);
  s.stop();
}

}  // namespace
}  // namespace chimera
