// A subsystem with module processes whose run was killed (issue 15, item 3) starts again at once,
// with nothing removed by hand: after SIGKILL of every process (the main one and its workers), and
// after SIGKILL of the main process alone, whose workers then end by themselves. The test is the
// workers' subreaper, so that it sees them end and reaps them, whoever their parent was. And a
// worker stopped by SIGSTOP between its cycles, which no heartbeat shows: its tasks go to ERROR.

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "chimera_process.hpp"
#include "run_chimera.hpp"

namespace chimera {
namespace {

using namespace std::chrono_literals;
using test::ChimeraProcess;
using test::TempDir;

std::string region_path(const std::string& name) { return "/dev/shm/chimera_" + name; }

// Figure 4's loop with its trajectory generator in a module process of its own.
std::string file_text(const std::string& name) {
  return "subsystem: " + name +
         "\n"
         "scheduler: rm\n"
         "tasks:\n"
         "  - {name: traj, module: joint_traj_gen, period: 2ms, criticality: soft, process: planner}\n"
         "  - {name: pid, module: pid_joint, period: 2ms, criticality: soft}\n"
         "  - {name: robot, module: robot_torque, period: 2ms, criticality: soft}\n";
}

// The children of `pid` (its workers), from /proc.
std::vector<pid_t> children_of(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
  std::vector<pid_t> out;
  for (pid_t child = 0; in >> child;) out.push_back(child);
  return out;
}

// Waits (bounded: a liveness bound, not a timing figure) for a run's region and its one worker.
std::vector<pid_t> wait_for_worker(const ChimeraProcess& run, pid_t main_pid, const std::string& name) {
  for (int i = 0; i < 3000; ++i) {
    const auto children = children_of(main_pid);
    if (std::filesystem::exists(region_path(name)) && !children.empty()) return children;
    std::this_thread::sleep_for(10ms);
  }
  ADD_FAILURE() << "no worker within 30 s: " << run.err();
  return {};
}

// Reaps `pid` once it ends, as this test's child (subreaper) or its run's; false if it did not
// end within 30 s.
bool reap_within_bound(pid_t pid) {
  for (int i = 0; i < 3000; ++i) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return true;
    if (r < 0 && errno == ECHILD && ::kill(pid, 0) != 0 && errno == ESRCH) return true;  // its run reaped it
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

class KilledRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(::prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
    name_ = "killed_run_" + std::to_string(::getpid());
    path_ = dir_.file("killed_run.yaml");
    test::write_text(path_, file_text(name_));
  }
  void TearDown() override {
    std::filesystem::remove(region_path(name_));
    (void)::prctl(PR_SET_CHILD_SUBREAPER, 0);
  }

  // A new run of the same file starts at once, its worker runs, and `quit` ends it cleanly.
  void starts_again_and_quits() {
    ChimeraProcess again(dir_, {"run", path_});
    const auto workers = wait_for_worker(again, again.pid(), name_);
    ASSERT_EQ(workers.size(), 1U) << again.err();
    again.send("status\nquit\n");
    EXPECT_EQ(again.wait_exit(), 0) << again.err();
    EXPECT_NE(again.out().find("traj"), std::string::npos) << again.out();
    EXPECT_EQ(again.err().find("error"), std::string::npos) << again.err();
    EXPECT_FALSE(std::filesystem::exists(region_path(name_))) << "a clean end leaves nothing";
    for (const pid_t w : workers) EXPECT_TRUE(reap_within_bound(w)) << "worker " << w;
  }

  TempDir dir_;
  std::string name_;
  std::string path_;
};

TEST_F(KilledRunTest, EveryProcessKilledStartsAgainAtOnce) {
  {
    ChimeraProcess run(dir_, {"run", path_});
    const auto workers = wait_for_worker(run, run.pid(), name_);
    ASSERT_FALSE(workers.empty());
    for (const pid_t w : workers) ::kill(w, SIGKILL);
    ::kill(run.pid(), SIGKILL);
    EXPECT_EQ(run.wait_exit(), -1);
    for (const pid_t w : workers) EXPECT_TRUE(reap_within_bound(w)) << "worker " << w;
  }
  ASSERT_TRUE(std::filesystem::exists(region_path(name_))) << "SIGKILL leaves the region behind";
  starts_again_and_quits();
}

TEST_F(KilledRunTest, MainProcessKilledItsWorkersEndByThemselves) {
  {
    ChimeraProcess run(dir_, {"run", path_});
    const auto workers = wait_for_worker(run, run.pid(), name_);
    ASSERT_FALSE(workers.empty());
    ::kill(run.pid(), SIGKILL);
    EXPECT_EQ(run.wait_exit(), -1);
    // The worker sees its command socket's end and exits: nobody left to read its tasks.
    for (const pid_t w : workers) EXPECT_TRUE(reap_within_bound(w)) << "worker " << w << " outlived its run";
  }
  starts_again_and_quits();
}

// SIGSTOP between two cycles: no task is inside a method, so no heartbeat runs long, yet the
// worker runs nothing. The supervisor sees it stopped past the stuck bound (200 ms here) and kills
// it, as a stuck task's process: its task is in ERROR with the reason, the rest runs on, and clear
// brings it back in a new worker.
TEST_F(KilledRunTest, AWorkerStoppedBySigstopIsKilledAndItsTaskGoesToError) {
  ChimeraProcess run(dir_, {"run", path_});
  const auto workers = wait_for_worker(run, run.pid(), name_);
  ASSERT_EQ(workers.size(), 1U) << run.err();
  // Running, not starting (a worker stopped before it is ready is the start's own time-out).
  run.send("status\n");
  bool running = false;
  for (int i = 0; i < 3000 && !running; ++i) {
    running = run.out().find("traj ") != std::string::npos;
    if (!running) std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(running) << run.err();
  ASSERT_EQ(::kill(workers[0], SIGSTOP), 0);
  const std::string said = "traj: ERROR: its process planner died (killed by the supervisor: stopped by a signal for ";
  // The kill's event is printed by the event log's own thread: it may come after the ERROR line.
  const std::string event = "process planner: stopped by a signal for ";
  bool seen = false;
  for (int i = 0; i < 3000 && !seen; ++i) {  // a liveness bound, not a timing figure
    const std::string err = run.err();
    seen = err.find(said) != std::string::npos && err.find(event) != std::string::npos;
    if (!seen) std::this_thread::sleep_for(10ms);
  }
  EXPECT_NE(run.err().find(said), std::string::npos) << run.err();
  EXPECT_NE(run.err().find(event), std::string::npos) << run.err();
  EXPECT_TRUE(reap_within_bound(workers[0])) << "the stopped worker was not killed";
  run.send("status\nclear traj\non traj\nstatus\nquit\n");
  EXPECT_EQ(run.wait_exit(), 0) << run.err();
  const std::string out = run.out();
  // The status after the stop: traj in ERROR; the last: traj ON again (its last error kept, as
  // what was cleared).
  std::vector<std::string> states;  // traj's state in each status, in order
  std::istringstream lines(run.out());
  for (std::string line; std::getline(lines, line);) {
    std::istringstream cells(line);
    std::string task, module, state;
    if (cells >> task >> module >> state && task == "traj" && module == "joint_traj_gen") states.push_back(state);
  }
  // Three statuses and the closing table.
  EXPECT_EQ(states, (std::vector<std::string>{"ON", "ERROR", "ON", "ON"})) << run.out();
  for (const pid_t w : children_of(run.pid())) EXPECT_TRUE(reap_within_bound(w)) << "worker " << w;
}

}  // namespace
}  // namespace chimera
