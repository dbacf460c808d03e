// The chimera command as users script it (contract section 2): exit codes, messages, runs.

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_chimera.hpp"
#include "support/json_text.hpp"
#include "support/text_search.hpp"

namespace chimera::test {
namespace {

const std::string kData = CLI_DATA_DIR;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class CliTest : public ::testing::Test {
 protected:
  Outcome chimera(const std::string& args, const std::string& input = {}, const std::string& prefix = {}) {
    return run_chimera(dir_, args, input, prefix);
  }
  static std::string data(const std::string& name) { return quoted(kData + "/" + name); }
  std::string copy(const std::string& name) { return quoted(private_copy(dir_, name)); }

  TempDir dir_;
};

// The output travels with a wrong exit code: it says why.
// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

TEST_F(CliTest, VerifyLegalFileExitsZero) {
  const auto o = chimera("verify " + data("fig4.yaml"));
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "fig4.yaml: 1 configuration legal")) << o.out;
}

TEST_F(CliTest, VerifyIllegalFileExitsOneWithOneLinePerViolation) {
  const auto o = chimera("verify " + data("illegal.yaml"));
  EXPECT_EXIT_CODE(o, 1);
  // pid reads theta_d and dtheta_d, which nothing produces in no_traj: two rule-2 lines.
  int lines = 0;
  for (const char* variable : {"theta_d", "dtheta_d"}) {
    const auto line_start = o.out.find(std::string("rule 2: ") + variable);
    ASSERT_NE(line_start, std::string::npos) << o.out;
    const auto line = o.out.substr(o.out.rfind('\n', line_start) + 1);
    EXPECT_TRUE(contains(line.substr(0, line.find('\n')), "pid")) << line;
    ++lines;
  }
  EXPECT_EQ(lines, 2);
  EXPECT_TRUE(contains(o.out, "no_traj")) << o.out;
}

TEST_F(CliTest, VerifyOneConfiguration) {
  EXPECT_EXIT_CODE(chimera("verify " + data("illegal.yaml") + " --config full"), 0);
  EXPECT_EXIT_CODE(chimera("verify " + data("illegal.yaml") + " --config no_traj"), 1);
  const auto unknown = chimera("verify " + data("illegal.yaml") + " --config nosuch");
  EXPECT_EXIT_CODE(unknown, 2);
  EXPECT_TRUE(contains(unknown.err, "nosuch")) << unknown.err;
}

TEST_F(CliTest, VerifyBadFileNamesFileLineAndKey) {
  auto o = chimera("verify " + data("bad_period.yaml"));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "bad_period.yaml:8: tasks[1].period")) << o.err;
  EXPECT_EQ(o.out, "");

  o = chimera("verify " + data("unknown_key.yaml"));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "unknown_key.yaml:5: tasks[0].perod")) << o.err;

  o = chimera("verify " + data("no_such_file.yaml"));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "no_such_file.yaml")) << o.err;
}

// Found by the fuzzer: yaml-cpp 0.7 loops for ever on a ',' outside brackets (jbeder/yaml-cpp#1040).
TEST_F(CliTest, AStrayCommaIsASyntaxErrorWithExitTwo) {
  const std::string file = dir_.file("comma.yaml");
  write_text(file, "# a subsystem file\n,\n");
  for (const std::string verb : {"verify ", "analyze "}) {
    auto o = chimera(verb + quoted(file));
    EXPECT_EXIT_CODE(o, 2);
    EXPECT_TRUE(contains(o.err, file + ":2: YAML syntax error: the parser cannot go on from here")) << verb << o.err;
  }
}

// Only regular files are read: a FIFO without a writer would block, /dev/zero never end.
TEST_F(CliTest, WhatIsNotARegularFileIsRefusedUnreadWithExitTwo) {
  const std::string fifo = dir_.file("fifo.yaml");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const auto& [file, kind] : std::vector<std::pair<std::string, std::string>>{
           {fifo, "a FIFO"}, {"/dev/zero", "a character device"}, {dir_.path(), "a directory"}}) {
    for (const std::string verb : {"verify ", "analyze ", "run "}) {
      auto o = chimera(verb + quoted(file) + (verb == "run " ? " --clock virtual --for 10ms" : ""));
      EXPECT_EXIT_CODE(o, 2);
      EXPECT_TRUE(contains(o.err, file + ": is " + kind + ", not a subsystem file")) << verb << o.err;
    }
  }
}

TEST_F(CliTest, ModulesListsThePaperModules) {
  const auto o = chimera("modules");
  EXPECT_EXIT_CODE(o, 0);
  for (const char* name : {"joint_traj_gen", "pid_joint", "robot_torque"})
    EXPECT_TRUE(contains(o.out, std::string("\n") + name + " ")) << name << "\n" << o.out;
}

TEST_F(CliTest, ModulesShowsOneModule) {
  const auto o = chimera("modules pid_joint");
  EXPECT_EXIT_CODE(o, 0);
  for (const char* part :
       {"pid_joint: ", "ports:", "in-const", "ndof", "in-var", "theta_d", "out-var", "tau_r", "params:", "kp"})
    EXPECT_TRUE(contains(o.out, part)) << part << "\n" << o.out;
}

TEST_F(CliTest, ModulesKeepsThePageLayoutOfCodeAndTables) {
  const auto o = chimera("modules pid_joint");
  EXPECT_EXIT_CODE(o, 0);
  // Indented code keeps its indent and its column alignment.
  EXPECT_TRUE(contains(o.out, "\n    e_i     = theta_d_i - theta_m_i\n")) << o.out;
  // A page line of 100 columns stays one line, though its ⁻¹ take more bytes than columns.
  EXPECT_TRUE(contains(o.out, "and `i_max` lets the\nintegral supply")) << o.out;
}

TEST_F(CliTest, ModulesUnknownNameExitsTwo) {
  const auto o = chimera("modules nosuch");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "nosuch")) << o.err;
}

TEST_F(CliTest, BadCommandLineExitsTwo) {
  const std::vector<std::string> bad{"",
                                     "frobnicate",
                                     "verify",
                                     "run",
                                     "modules a b",
                                     "run " + data("fig4.yaml") + " --clock sometimes",
                                     "run " + data("fig4.yaml") + " --for 10",
                                     "verify " + data("fig4.yaml") + " --bogus"};
  for (const auto& args : bad) {
    const auto o = chimera(args);
    EXPECT_EXIT_CODE(o, 2);
    EXPECT_FALSE(o.err.empty()) << args;
  }
  EXPECT_EXIT_CODE(chimera("--help"), 0);
}

TEST_F(CliTest, RunScriptedOnTheVirtualClock) {
  const auto o = chimera("run " + copy("fig4.yaml") + " --clock virtual --for 2s",
                         "status\n"
                         "# a comment and a blank line\n"
                         "\n"
                         "get theta_m\n"
                         "wait 1s\n"
                         "stats\n"
                         "quit\n"
                         "status\n");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(o.err.empty()) << o.err;
  // status: a table, every task ON, nothing run yet
  EXPECT_EQ(o.out.rfind("task ", 0), 0U) << o.out;
  // The row as printed, spacing included, but for the cpu column's right-aligned number (the
  // automatic assignment, which depends on the machine's CPUs).
  const std::string start = "pid    pid_joint       ON  ";
  const std::string end = "    1 ms       0       0";
  const std::string row = test::line_starting(o.out, start).value_or("");
  const std::string cpu = row.size() > start.size() + end.size() && row.ends_with(end)
                              ? row.substr(start.size(), row.size() - start.size() - end.size())
                              : "";
  EXPECT_TRUE(test::only_of(cpu.substr(std::min(cpu.size(), cpu.find_first_not_of(' '))), "0123456789")) << o.out;
  EXPECT_TRUE(contains(o.out, "theta_m = [")) << o.out;
  // stats after 1 s simulated: the timing table with 1000 cycles of the 1 ms tasks
  EXPECT_TRUE(contains(o.out, "latency p99")) << o.out;
  EXPECT_TRUE(contains(o.out, "  1000  ")) << o.out;
  // quit stops at once: the `status` after it is never read, the final table still printed
  EXPECT_EQ(o.out.find("task   module          state  cpu  period  cycles  missed\n", 1), std::string::npos) << o.out;
}

TEST_F(CliTest, RunRepliesToBadCommandsAndGoesOn) {
  const auto o = chimera("run " + copy("fig4.yaml") + " --clock virtual --for 10ms",
                         "bogus\non pid nosuch\nset theta_m 1 2 3 4 5 6\nswitch other\nget theta_d\n");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "unknown command 'bogus' (try help)\n")) << o.out;
  EXPECT_TRUE(contains(o.out, "unknown task 'nosuch'\n")) << o.out;
  EXPECT_TRUE(contains(o.out, "theta_m is produced by task 'robot'")) << o.out;
  EXPECT_TRUE(contains(o.out, ": no configuration named other (configurations: pid_control)\n")) << o.out;
  EXPECT_TRUE(contains(o.out, "theta_d = [")) << o.out;
}

TEST_F(CliTest, RunWritesStatsJsonAndRunsOnUntilFor) {
  const std::string json = dir_.file("stats.json");
  const auto o = chimera("run " + copy("fig4.yaml") + " --clock virtual --for 2s --stats-json " + quoted(json),
                         "status\nwait 1s\n");
  EXPECT_EXIT_CODE(o, 0);
  ASSERT_TRUE(std::filesystem::exists(json));
  const auto doc = test::parse_json(read_text(json));
  EXPECT_EQ(doc.at("clock"), "virtual");
  EXPECT_EQ(doc.at("switches"), 0);
  for (const char* task : {"traj", "pid", "robot"}) {
    const auto& t = doc.at("tasks").at(task);
    EXPECT_EQ(t.at("state"), "ON") << task;
    for (const char* key : {"cycles", "missed"}) EXPECT_TRUE(t.at(key).is_number_unsigned()) << task << key;
    for (const char* key : {"mean", "max"}) EXPECT_TRUE(t.at("exec_ns").at(key).is_number()) << task << key;
    for (const char* key : {"p50", "p99", "max"}) EXPECT_TRUE(t.at("latency_ns").at(key).is_number()) << task << key;
  }
  // 2 s of simulated time at 1 ms, and 10 ms for the trajectory generator
  EXPECT_NEAR(doc.at("tasks").at("pid").at("cycles").get<double>(), 2000, 2);
  EXPECT_NEAR(doc.at("tasks").at("robot").at("cycles").get<double>(), 2000, 2);
  EXPECT_NEAR(doc.at("tasks").at("traj").at("cycles").get<double>(), 200, 1);
  // the timing table at the end says the same
  EXPECT_TRUE(contains(o.out, "exec mean")) << o.out;
}

TEST_F(CliTest, RunIsDeterministicOnTheVirtualClock) {
  const std::string script = "wait 500ms\nget theta_m\nget tau_r\n";
  const auto first = chimera("run " + copy("fig4.yaml") + " --clock virtual --for 1s", script);
  const auto second = chimera("run " + copy("fig4.yaml") + " --clock virtual --for 1s", script);
  EXPECT_EXIT_CODE(first, 0);
  auto values = [](const std::string& out) {
    const auto begin = out.find("theta_m = ");
    return begin == std::string::npos ? std::string() : out.substr(begin, out.find("task ", begin) - begin);
  };
  EXPECT_FALSE(values(first.out).empty()) << first.out;
  EXPECT_EQ(values(first.out), values(second.out));
}

TEST_F(CliTest, RunInvalidFileOrConfigurationExitsTwo) {
  auto o = chimera("run " + data("bad_period.yaml") + " --clock virtual --for 10ms");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "bad_period.yaml:8: tasks[1].period")) << o.err;
  EXPECT_EQ(o.out, "");

  o = chimera("run " + copy("fig4.yaml") + " --clock virtual --for 10ms --config nosuch");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "nosuch")) << o.err;

  // An illegal start configuration is refused before anything starts.
  o = chimera("run " + copy("illegal.yaml") + " --clock virtual --for 10ms --config no_traj");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "rule 2")) << o.err;
  EXPECT_EQ(o.out, "");

  o = chimera("run " + copy("fig4.yaml") + " --clock virtual --for 10ms --stats-json /nonexistent-dir/s.json");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "/nonexistent-dir/s.json")) << o.err;
}

TEST_F(CliTest, RunStopsCleanlyOnSigterm) {
  // The real clock, no --for and stdin at its end: only the signal ends the run. Three seconds
  // leave a sanitized build on a loaded machine time to start; a signal that comes earlier is
  // handled the same way.
  // Every task soft: on a loaded machine a hard task may miss a deadline, which would make it exit 1.
  const std::string file = private_copy(dir_, "fig4.yaml");
  write_text(file, test::replace_every(read_text(file), "period: 1ms", "period: 1ms\n    criticality: soft"));
  const auto o = chimera("run " + quoted(file), "", "timeout --preserve-status -s TERM 3");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "latency p99")) << o.out;
}

TEST_F(CliTest, OnTheVirtualClockWithoutForARunStopsAtTheEndOfItsInput) {
  // Simulated time without --for has no end of its own: it used to run on until a signal,
  // spinning a core. Now the run lasts as long as its input: 200 ms of simulated time here.
  // (timeout: a run that spins on is killed and fails the test, rather than hanging it.)
  const auto o = chimera("run " + copy("fig4.yaml") + " --clock virtual", "wait 200ms\nget theta_m\n", "timeout 120");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "theta_m = [")) << o.out;
  const auto pid_row = test::fields_of(test::line_starting(o.out, "pid ").value_or(""));
  ASSERT_GE(pid_row.size(), 6U) << o.out;
  EXPECT_EQ(std::vector<std::string>(pid_row.begin(), pid_row.begin() + 5),
            (std::vector<std::string>{"pid", "pid_joint", "ON", "1", "ms"}))
      << o.out;
  EXPECT_TRUE(pid_row[5] == "200" || pid_row[5] == "201") << o.out;
  // No input at all: it stops at once, with its (empty) figures.
  const auto empty = chimera("run " + copy("fig4.yaml") + " --clock virtual", "", "timeout 120");
  EXPECT_EXIT_CODE(empty, 0);
  EXPECT_TRUE(contains(empty.out, "latency p99")) << empty.out;
}

TEST_F(CliTest, RunOnTheRealClock) {
  // Timing figures are for benchmarks; here only that the run starts, cycles and stops cleanly.
  const std::string json = dir_.file("stats.json");
  const auto o = chimera("run " + copy("fig4.yaml") + " --for 300ms --stats-json " + quoted(json), "status\n");
  EXPECT_EXIT_CODE(o, 0);
  const auto doc = test::parse_json(read_text(json));
  EXPECT_EQ(doc.at("clock"), "real");
  EXPECT_GT(doc.at("tasks").at("pid").at("cycles").get<int>(), 0);
}

TEST_F(CliTest, WithoutRealTimePrivilegeItWarnsOnceAndRunsOnOrdinaryThreads) {
  // Root: setpriv drops CAP_SYS_NICE, so SCHED_FIFO is refused. Others: a zero rtprio limit.
  const std::string unprivileged =
      ::geteuid() == 0 ? "setpriv --inh-caps=-sys_nice --bounding-set=-sys_nice" : "prlimit --rtprio=0:0";
  const auto o = chimera("run " + copy("fig4.yaml") + " --for 200ms", "", unprivileged);
  EXPECT_EXIT_CODE(o, 0);
  std::size_t warnings = 0;
  for (std::size_t at = o.err.find("SCHED_FIFO is not permitted"); at != std::string::npos;
       at = o.err.find("SCHED_FIFO is not permitted", at + 1))
    ++warnings;
  EXPECT_EQ(warnings, 1u) << o.err;
  EXPECT_NE(o.out.find("pid"), std::string::npos) << "the timing table is printed";
}

}  // namespace
}  // namespace chimera::test
