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

#include "chimera_process.hpp"
#include "run_chimera.hpp"

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
                             "    period: 2ms\n"
                             "    criticality: soft\n"
                             "    params: {after: 25}\n");
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
  // Stuck from its 25th cycle on (50 ms in); the stop comes well after.
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

TEST(StuckTask, ForEndsTheRunWithTheStuckTaskLeftBehind) { ends_with_the_stuck_task_left_behind(End::kFor); }
TEST(StuckTask, QuitEndsTheRunWithTheStuckTaskLeftBehind) { ends_with_the_stuck_task_left_behind(End::kQuit); }
TEST(StuckTask, SigtermEndsTheRunWithTheStuckTaskLeftBehind) { ends_with_the_stuck_task_left_behind(End::kSigterm); }

}  // namespace
}  // namespace chimera
