// A task of the main process stuck in a method (issue 15, item 5): `--for`, `quit` and SIGTERM
// still end the run, within a bound: the stop waits a second for the stuck thread's answer and a
// second more for the thread, then leaves it behind. The run exits 1 and says which task was left
// behind; its region is gone from /dev/shm; the other tasks ran on and are reported as usual.

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "chimera_process.hpp"
#include "exec/task_shared.hpp"
#include "run_chimera.hpp"
#include "support/json_text.hpp"

namespace chimera {
namespace {

using test::ChimeraProcess;
using test::TempDir;

// A bound on the whole run's end, not a timing figure: the stop itself takes about 2 s, and the
// rest is room for a loaded machine. Without the bound the run never ends.
constexpr int kEndsWithinMs = 30'000;

std::string write_file(const TempDir& dir, const std::string& name) {
  std::string path = dir.file(name + ".yaml");
  test::write_text(path, "subsystem: " + name +
                             "\n"
                             "plugins: [" FAULTY_PLUGIN
                             "]\n"
                             "tasks:\n"
                             "  - {name: load, module: cpu_load, period: 1ms, criticality: soft}\n"
                             "  - name: spin\n"
                             "    module: loop_in_cycle\n"
                             "    period: 100ms\n"
                             "    criticality: soft\n"
                             "    params: {after: 2}\n");
  return path;
}

// How the run is ended: --for, quit on stdin, SIGTERM.
enum class End { kFor, kQuit, kSigterm };

void ends_with_the_stuck_task_left_behind(End end) {
  TempDir dir;
  const std::string name = "stuck_" + std::to_string(::getpid()) + "_" + std::to_string(static_cast<int>(end));
  const std::string file = write_file(dir, name);
  std::vector<std::string> args{"run", file};
  if (end == End::kFor) args.insert(args.end(), {"--for", "500ms"});
  ChimeraProcess run(dir, args);
  // Stuck from its 2nd cycle on (200 ms in); the stop comes after that and before the watch gives
  // the cycle up (ten periods, 1 s; the test below is of that).
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  if (end == End::kQuit) run.send("quit\n");
  if (end == End::kSigterm) {
    ASSERT_EQ(::kill(run.pid(), SIGTERM), 0);
  }
  const int code = run.wait_exit(kEndsWithinMs);
  ASSERT_NE(code, -1) << "the run did not end within " << kEndsWithinMs << " ms\n" << run.err();
  EXPECT_EQ(code, 1) << run.err();
  const std::string err = run.err();
  EXPECT_NE(err.find("spin stuck in a method when the run stopped: its thread was left behind, and the process "
                     "ends without it"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("task spin: its thread has not answered since an earlier signal (a method is stuck?)"),
            std::string::npos)
      << err;
  EXPECT_FALSE(std::filesystem::exists("/dev/shm/chimera_" + name)) << "the region was left behind";
  // The timing table: a row for each task.
  const std::string out = run.out();
  EXPECT_NE(out.find("load "), std::string::npos) << out;
  EXPECT_NE(out.find("spin "), std::string::npos) << out;
}

// The watch (stuck_methods.cpp): spin, stuck in cycle() from its 25th cycle (50 ms in), shares
// its thread with load (one CPU and one period under rm). Once it has been inside that cycle ten
// periods, and at least the floor, it is ERROR and load goes on, on a thread of its own; without
// the watch load stops with it, after its 25 cycles.
TEST(StuckTask, AStuckCycleIsGivenUpAndItsThreadMateRunsOn) {
  TempDir dir;
  const std::string name = "given_up_" + std::to_string(::getpid());
  const std::string file = dir.file(name + ".yaml");
  test::write_text(file, "subsystem: " + name +
                             "\n"
                             "plugins: [" FAULTY_PLUGIN
                             "]\n"
                             "tasks:\n"
                             "  - {name: load, module: cpu_load, period: 2ms, cpu: 0, criticality: soft}\n"
                             "  - {name: spin, module: loop_in_cycle, period: 2ms, cpu: 0, criticality: soft,"
                             " params: {after: 25}}\n");
  // The watch gives up at about 50 ms + the floor; load then runs for the last 1.5 s at least.
  const std::int64_t given_up_ms = 50 + StuckBound::kCycleFloorNs / 1'000'000;
  const std::int64_t run_ms = given_up_ms + 1'500;
  const std::string stats = dir.file("stats.json");
  ChimeraProcess run(dir, {"run", file, "--for", std::to_string(run_ms) + "ms", "--stats-json", stats});
  // Once given up, the task cannot be signalled: clear is refused at once, and says why.
  std::this_thread::sleep_for(std::chrono::milliseconds(given_up_ms + 500));
  run.send("clear spin\n");
  const int code = run.wait_exit(kEndsWithinMs + static_cast<int>(run_ms));
  ASSERT_NE(code, -1) << "the run did not end\n" << run.err();
  EXPECT_NE((run.out() + run.err())
                .find("spin: stuck in cycle(), and given up: a task of the main process cannot be "
                      "stopped or restarted"),
            std::string::npos)
      << run.out() << run.err();
  EXPECT_EQ(code, 1) << run.err();  // spin's thread is left behind at the stop, still in its cycle
  const std::string err = run.err();
  EXPECT_NE(err.find("ERROR: stuck in cycle() for"), std::string::npos) << err;
  EXPECT_NE(err.find("given up: its thread drops to SCHED_IDLE, and load moved to a new thread"), std::string::npos)
      << err;
  const auto doc = test::parse_json(test::read_text(stats));
  EXPECT_EQ(doc.at("tasks").at("spin").at("state"), "ERROR");
  EXPECT_EQ(doc.at("tasks").at("load").at("state"), "ON");  // the statistics are of the run, before the stop
  // 750 cycles in the last 1.5 s alone; a loaded machine may run fewer, never only the first 25.
  EXPECT_GE(doc.at("tasks").at("load").at("cycles").get<long>(), 300) << run.out();
  EXPECT_FALSE(std::filesystem::exists("/dev/shm/chimera_" + name)) << "the region was left behind";
}

// The same for a method a signal runs: `on stuck` never returns from on(). The signal answers
// after its 10 s that it had no answer; the watch then gives on() up (its bound is the same 10 s):
// stuck is ERROR, and load, its thread-mate (one CPU and one period), which the stuck thread held
// from the signal on, goes on on a thread of its own. Without it load never cycles again.
TEST(StuckTask, AStuckOnIsGivenUpAndItsThreadMateRunsOn) {
  TempDir dir;
  const std::string name = "stuck_on_" + std::to_string(::getpid());
  const std::string file = dir.file(name + ".yaml");
  test::write_text(file, "subsystem: " + name +
                             "\n"
                             "plugins: [" FAULTY_PLUGIN
                             "]\n"
                             "tasks:\n"
                             "  - {name: load, module: cpu_load, period: 2ms, cpu: 0, criticality: soft}\n"
                             "  - {name: stuck, module: loop_in_on, period: 2ms, cpu: 0, criticality: soft}\n"
                             "configurations:\n"
                             "  calm: [load]\n"
                             "  both: [load, stuck]\n");
  // on at 300 ms; given up 10 s later; then load runs for 2.5 s more at least.
  const std::int64_t on_at_ms = 300;
  const std::int64_t run_ms = on_at_ms + StuckBound::kMethodNs / 1'000'000 + 2'500;
  const std::string stats = dir.file("stats.json");
  ChimeraProcess run(dir, {"run", file, "--for", std::to_string(run_ms) + "ms", "--stats-json", stats});
  std::this_thread::sleep_for(std::chrono::milliseconds(on_at_ms));
  run.send("spawn stuck\non stuck\n");
  // Once given up, the task cannot be signalled: clear is refused at once, and says why.
  std::this_thread::sleep_for(std::chrono::milliseconds(StuckBound::kMethodNs / 1'000'000 + 1'000));
  run.send("clear stuck\n");
  const int code = run.wait_exit(kEndsWithinMs + static_cast<int>(run_ms));
  ASSERT_NE(code, -1) << "the run did not end\n" << run.err();
  const std::string said = run.out() + run.err();
  EXPECT_NE(said.find("stuck: no answer within 10.000 s (a method is stuck?)"), std::string::npos) << said;
  EXPECT_NE(said.find("stuck: stuck in on(), and given up: a task of the main process cannot be stopped or restarted"),
            std::string::npos)
      << said;
  EXPECT_EQ(code, 1) << run.err();  // stuck's thread is left behind at the stop, still in on()
  const std::string err = run.err();
  EXPECT_NE(err.find("ERROR: stuck in on() for"), std::string::npos) << err;
  EXPECT_NE(err.find("given up: its thread drops to SCHED_IDLE, and load moved to a new thread"), std::string::npos)
      << err;
  const auto doc = test::parse_json(test::read_text(stats));
  EXPECT_EQ(doc.at("tasks").at("stuck").at("state"), "ERROR");
  EXPECT_EQ(doc.at("tasks").at("load").at("state"), "ON");
  // 150 cycles before the signal, none for the 10 s it held the thread, then 1,250 in the last
  // 2.5 s alone; a loaded machine may run fewer, never only the first 150.
  EXPECT_GE(doc.at("tasks").at("load").at("cycles").get<long>(), 600) << run.out();
  EXPECT_FALSE(std::filesystem::exists("/dev/shm/chimera_" + name)) << "the region was left behind";
}

TEST(StuckTask, ForEndsTheRunWithTheStuckTaskLeftBehind) { ends_with_the_stuck_task_left_behind(End::kFor); }
TEST(StuckTask, QuitEndsTheRunWithTheStuckTaskLeftBehind) { ends_with_the_stuck_task_left_behind(End::kQuit); }
TEST(StuckTask, SigtermEndsTheRunWithTheStuckTaskLeftBehind) { ends_with_the_stuck_task_left_behind(End::kSigterm); }

}  // namespace
}  // namespace chimera
