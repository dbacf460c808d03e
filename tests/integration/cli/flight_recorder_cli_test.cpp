// The flight recorder through chimera run (docs/flight-recorder.md): the dump a task's ERROR
// makes by itself, the operator's `dump`, --dump-at-exit, and --record off. On the virtual clock,
// so that which cycle misses is exact.

#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "run_chimera.hpp"

namespace chimera::test {
namespace {

namespace fs = std::filesystem;

// A trajectory generator and a position-mode robot beside a hard task whose 200th cycle overruns its 1 ms period.
std::string subsystem_file(const TempDir& dir) {
  const std::string name = "recorder_" + std::to_string(::getpid());
  const std::string path = dir.file("recorder.yaml");
  write_text(path, "subsystem: " + name +
                       "\n"
                       "tasks:\n"
                       "  - {name: traj, module: joint_traj_gen, period: 1ms}\n"
                       "  - {name: robot, module: robot_position, period: 1ms}\n"
                       "  - name: load\n"
                       "    module: cpu_load\n"
                       "    period: 1ms\n"
                       "    criticality: hard\n"
                       "    params: {exec: 0.0001, overrun_every: 200, overrun: 0.002}\n"
                       "configurations:\n"
                       "  all: [traj, robot, load]\n");
  return path;
}

std::size_t lines_of(const std::string& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

// The one dump directory the run made below `dumps` ("" if none).
std::string the_dump(const std::string& dumps) {
  std::string made;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dumps, ec)) made = entry.path().string();
  return made;
}

// Three hard tasks on one CPU whose 200th cycles overrun: the first misses its deadline and the two
// behind it miss theirs, a few milliseconds apart. They entered ERROR together: one dump for the
// three, not a dump each (with thousands of tasks failing at once a dump each held the run for
// minutes), naming all three.
TEST(FlightRecorderCli, TasksEnteringErrorTogetherShareOneDump) {
  TempDir dir;
  const std::string path = dir.file("three.yaml");
  std::string text = "subsystem: recorder3_" + std::to_string(::getpid()) + "\ncpus: [0]\ntasks:\n";
  for (int i = 0; i < 3; ++i)
    text += "  - {name: load" + std::to_string(i) +
            ", module: cpu_load, period: 1ms, criticality: hard, params: {exec: 0.0001, overrun_every: 200, "
            "overrun: 0.002}}\n";
  write_text(path, text);
  const std::string dumps = dir.file("dumps");
  const Outcome o = run_chimera(dir, "run " + quoted(path) + " --clock virtual --for 500ms --record 100ms --dump-dir " +
                                         quoted(dumps));
  EXPECT_EQ(o.exit_code, 1) << o.err;
  std::vector<std::string> made;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dumps, ec)) made.push_back(entry.path().string());
  ASSERT_EQ(made.size(), 1U) << o.err;
  EXPECT_NE(made[0].find("-load0-and-2-more-t"), std::string::npos) << made[0];
  const std::string summary = read_text(made[0] + "/summary.txt");
  EXPECT_NE(summary.find("why: load0 entered ERROR: "), std::string::npos) << summary;
  EXPECT_NE(summary.find("; and 2 more with it: load1, load2"), std::string::npos) << summary;
  for (const char* task : {"load0: ERROR", "load1: ERROR", "load2: ERROR"})
    EXPECT_NE(summary.find(task), std::string::npos) << summary;
  EXPECT_NE(o.err.find("load0: flight recorder: the last 0.1 s written to " + made[0] + "/ (2 more tasks entered "
                                                                                        "ERROR with it)"),
            std::string::npos)
      << o.err;
}

TEST(FlightRecorderCli, AHardTaskEnteringErrorDumpsTheLastSecondsByItself) {
  TempDir dir;
  const std::string file = subsystem_file(dir);
  const std::string dumps = dir.file("dumps");
  const Outcome o = run_chimera(dir, "run " + quoted(file) + " --clock virtual --for 500ms --record 100ms --dump-dir " +
                                         quoted(dumps));
  EXPECT_EQ(o.exit_code, 1) << o.err;  // a hard task failed
  ASSERT_TRUE(fs::is_directory(dumps)) << o.err;
  const std::string made = the_dump(dumps);
  ASSERT_FALSE(made.empty());
  EXPECT_NE(made.find("-load-t"), std::string::npos) << made;
  EXPECT_NE(o.err.find("load: flight recorder: the last 0.1 s written to " + made + "/"), std::string::npos) << o.err;
  const std::string summary = read_text(made + "/summary.txt");
  EXPECT_NE(summary.find("why: load entered ERROR"), std::string::npos) << summary;
  EXPECT_NE(summary.find("load: ERROR"), std::string::npos) << summary;
  EXPECT_NE(summary.find("traj: ON"), std::string::npos) << summary;
  // What ran, as `save` writes it: a file `chimera verify` accepts, with the failed task in it.
  const std::string ran = read_text(made + "/subsystem.yaml");
  EXPECT_NE(ran.find("name: load"), std::string::npos) << ran;
  const Outcome verified = run_chimera(dir, "verify " + quoted(made + "/subsystem.yaml"));
  EXPECT_EQ(verified.exit_code, 0) << verified.out << verified.err;
  // The robot's ndof, which no ring records, as a file's constants: map.
  const std::string constants = read_text(made + "/constants.yaml");
  EXPECT_NE(constants.find("\nconstants:\n  ndof: [6]\n"), std::string::npos) << constants;
  // 100 ms at 1 kHz: about 100 cycles of each of the three tasks, one of load's its missed one.
  const std::string timing = read_text(made + "/timing.csv");
  EXPECT_EQ(timing.rfind("task,t,latency_ns,exec_ns,response_ns,missed,overrun,failed,skipped\n", 0), 0U);
  EXPECT_NE(timing.find(",1,0,0,0\n"), std::string::npos) << "no missed cycle in the dump";
  const std::size_t rows = lines_of(made + "/timing.csv") - 1;
  EXPECT_GE(rows, 290U);
  EXPECT_LE(rows, 306U);
  const std::string variables = read_text(made + "/variables.csv");
  EXPECT_EQ(variables.rfind("t,dtheta_d[0],", 0), 0U) << variables.substr(0, 200);
  EXPECT_GE(lines_of(made + "/variables.csv"), 95U);
}

TEST(FlightRecorderCli, TheOperatorsDumpAndTheOneAtExitWriteWhereTheyAreTold) {
  TempDir dir;
  const std::string file = subsystem_file(dir);
  const std::string mine = dir.file("mine");
  const Outcome o = run_chimera(dir,
                                "run " + quoted(file) + " --clock virtual --for 150ms --dump-at-exit --dump-dir " +
                                    quoted(dir.file("dumps")),
                                "wait 50ms\ndump " + mine + "\n");
  EXPECT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE(o.out.find("the last 10 s written to " + mine + "/"), std::string::npos) << o.out;
  EXPECT_NE(read_text(mine + "/summary.txt").find("why: the operator's dump"), std::string::npos);
  // 50 ms of three tasks at 1 kHz, each cycle once.
  EXPECT_GE(lines_of(mine + "/timing.csv") - 1, 150U);
  EXPECT_LE(lines_of(mine + "/timing.csv") - 1, 156U);
  const std::string at_exit = read_text(dir.file("dumps") + "/recorder_" + std::to_string(::getpid()) + "-exit/summary.txt");
  EXPECT_NE(at_exit.find("why: the run's end"), std::string::npos) << o.err;
}

TEST(FlightRecorderCli, WithTheRecorderOffDumpIsRefusedAndNothingIsWritten) {
  TempDir dir;
  const std::string file = subsystem_file(dir);
  const Outcome o = run_chimera(dir, "run " + quoted(file) + " --clock virtual --for 10ms --record off --dump-dir " +
                                         quoted(dir.file("dumps")),
                                "dump\n");
  EXPECT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE((o.out + o.err).find("dump: this run keeps no history (the flight recorder is off)"), std::string::npos)
      << o.out << o.err;
  EXPECT_FALSE(fs::exists(dir.file("dumps")));
}

// chimera replay: the task that entered ERROR, run again on its recorded inputs, enters it again
// at the same recorded release (cpu_load's 200th cycle overruns whatever its inputs; the dump's
// name says when the original did: -load-t0.201s).
TEST(FlightRecorderCli, ReplayBringsBackAFaultOfTheModuleAtItsRecordedRelease) {
  TempDir dir;
  const std::string file = subsystem_file(dir);
  const std::string dumps = dir.file("dumps");
  const Outcome o = run_chimera(dir, "run " + quoted(file) + " --clock virtual --for 500ms --record 300ms --dump-dir " +
                                         quoted(dumps));
  ASSERT_EQ(o.exit_code, 1) << o.err;
  const std::string made = the_dump(dumps);
  ASSERT_FALSE(made.empty()) << o.err;
  const Outcome replayed = run_chimera(dir, "replay " + quoted(made) + " --task load");
  EXPECT_EQ(replayed.exit_code, 1) << replayed.out << replayed.err;
  EXPECT_NE(replayed.out.find("replay: 'load' entered ERROR at the recorded t = 0.201"), std::string::npos)
      << replayed.out << replayed.err;
  const Outcome missing = run_chimera(dir, "replay " + quoted(made) + " --task nosuch");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("no task named 'nosuch' in the dump"), std::string::npos) << missing.err;
}

// A module without state of its own (forward kinematics) replayed on its recorded theta_m gives
// back its recorded x_m to within what one release's order changes (the original fk may have
// read the robot's theta_m of the release before; the player gives it the one of its release).
TEST(FlightRecorderCli, ReplayComparesATasksOutputsWithTheRecordedOnes) {
  TempDir dir;
  const std::string file = dir.file("fk.yaml");
  write_text(file, "subsystem: replay_fk_" + std::to_string(::getpid()) +
                       "\ntasks:\n"
                       "  - {name: traj, module: joint_traj_gen, period: 1ms}\n"
                       "  - {name: robot, module: robot_position, period: 1ms}\n"
                       "  - {name: fk, module: fwd_kin_jacobian, period: 1ms}\n");
  const std::string dumps = dir.file("dumps");
  const Outcome o = run_chimera(dir, "run " + quoted(file) + " --clock virtual --for 1s --record 300ms --dump-at-exit --dump-dir " +
                                         quoted(dumps));
  ASSERT_EQ(o.exit_code, 0) << o.err;
  const std::string made = the_dump(dumps);
  ASSERT_FALSE(made.empty()) << o.err;
  const Outcome replayed = run_chimera(dir, "replay " + quoted(made) + " --task fk");
  EXPECT_EQ(replayed.exit_code, 0) << replayed.out << replayed.err;
  EXPECT_NE(replayed.out.find("301 releases from t = 0.699 s, its inputs theta_m"), std::string::npos) << replayed.out;
  const auto at = replayed.out.find("x_m: at most ");
  ASSERT_NE(at, std::string::npos) << replayed.out;
  // fk has no state: on its recorded inputs it writes what it wrote, to the bit (log_player once
  // played a row now and then a release late, its time and the release's differing in the last
  // bits: up to 0.003 off).
  EXPECT_EQ(std::stod(replayed.out.substr(at + 13)), 0.0) << replayed.out;
  EXPECT_NE(replayed.out.find("over 301 releases"), std::string::npos) << replayed.out;
  EXPECT_NE(replayed.out.find("replay: 'fk' ran every release without a fault"), std::string::npos) << replayed.out;
}

// Figure 4's loop, cut before pid (listed first): at each instant pid runs before robot and reads
// robot's theta_m and dtheta_m of the release before, which the row of that instant does not hold.
// The replay plays each input as pid found it (the release order, timing.csv): with no integral
// (ki 0) pid has no state, and writes what it wrote, to the bit, at every release but the first
// (whose inputs were written before the window began, and which is not compared).
TEST(FlightRecorderCli, ReplayPlaysALoopsBackEdgeAsTheTaskFoundIt) {
  TempDir dir;
  const std::string file = dir.file("loop.yaml");
  write_text(file, "subsystem: replay_loop_" + std::to_string(::getpid()) +
                       "\ntasks:\n"
                       "  - {name: traj, module: joint_traj_gen, period: 1ms}\n"
                       "  - {name: pid, module: pid_joint, period: 1ms, params: {ki: [0, 0, 0, 0, 0, 0]}}\n"
                       "  - {name: robot, module: robot_torque, period: 1ms}\n");
  const std::string dumps = dir.file("dumps");
  const Outcome o =
      run_chimera(dir, "run " + quoted(file) + " --clock virtual --for 1s --record 300ms --dump-at-exit --dump-dir " +
                           quoted(dumps));
  ASSERT_EQ(o.exit_code, 0) << o.err;
  const std::string made = the_dump(dumps);
  ASSERT_FALSE(made.empty()) << o.err;
  const Outcome replayed = run_chimera(dir, "replay " + quoted(made) + " --task pid");
  EXPECT_EQ(replayed.exit_code, 0) << replayed.out << replayed.err;
  // theta_m and dtheta_m at each of the 300 releases after the first.
  EXPECT_NE(replayed.out.find("600 value(s) as the task found them"), std::string::npos) << replayed.out;
  EXPECT_NE(replayed.out.find("tau_r: at most 0 from the recorded over 300 releases"), std::string::npos)
      << replayed.out;
}

}  // namespace
}  // namespace chimera::test
