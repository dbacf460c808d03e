// chimera analyze as users script it (contract section 2): exit 0 feasible, 1 not, 2 invalid
// input; per CPU the tasks, utilisation, bound, C and its source, T, D, response time or reason.
// The files carry textbook task sets (see their first lines) with wcet: given, so the numbers
// are exact; one file has no wcet: and is measured on the virtual clock.

#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "run_chimera.hpp"

namespace chimera::test {
namespace {

const std::string kData = CLI_DATA_DIR;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The table row of `task` ("  name  placed ..."), or "" if there is none.
std::string row_of(const std::string& out, const std::string& task) {
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("  " + task + " ", 0) == 0) return line;
  return {};
}

class AnalyzeTest : public ::testing::Test {
 protected:
  Outcome analyze(const std::string& args) { return run_chimera(dir_, "analyze " + args); }
  Outcome chimera(const std::string& args) { return run_chimera(dir_, args); }
  [[nodiscard]] std::string path(const std::string& name) const { return dir_.file(name); }
  static std::string data(const std::string& name) { return quoted(kData + "/" + name); }
  std::string write(const std::string& name, const std::string& text) {
    write_text(dir_.file(name), text);
    return quoted(dir_.file(name));
  }

 private:
  TempDir dir_;
};

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

TEST_F(AnalyzeTest, RateMonotonicAboveTheBoundIsFeasible) {
  const auto o = analyze(data("analyze_rm_above_bound.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(o.err.empty()) << o.err;
  EXPECT_TRUE(contains(o.out,
                       "analyze_rm_above_bound.yaml: configuration 'default', 3 tasks under rm on cpu 0; every "
                       "C includes 0 ns of framework overhead per cycle\n"))
      << o.out;
  EXPECT_TRUE(contains(o.out,
                       "cpu 0: U = 0.883, Liu-Layland bound 0.780 for 3 tasks: above the bound; "
                       "response-time analysis decides\n"))
      << o.out;
  // In priority order, whatever the file's order: R = 1, 3, 10 ms.
  EXPECT_LT(o.out.find("  a "), o.out.find("  b "));
  EXPECT_LT(o.out.find("  b "), o.out.find("  c "));
  EXPECT_EQ(row_of(o.out, "a"), "  a     assigned  hard  1 ms  file   4 ms   4 ms      1 ms  meets") << o.out;
  EXPECT_EQ(row_of(o.out, "b"), "  b     assigned  hard  2 ms  file   6 ms   6 ms      3 ms  meets") << o.out;
  EXPECT_EQ(row_of(o.out, "c"), "  c     assigned  hard  3 ms  file  10 ms  10 ms     10 ms  meets") << o.out;
  EXPECT_TRUE(contains(o.out, "configuration 'default': feasible under rm\n")) << o.out;
  EXPECT_TRUE(contains(o.out, "/analyze_rm_above_bound.yaml: 1 configuration feasible\n")) << o.out;
}

TEST_F(AnalyzeTest, TheDefaultOverheadTipsATightSetOver) {
  // 1 µs per cycle on each of a, b and c: R(c) = 3.001 + 3 x 1.001 + 2 x 2.001 = 10.006 ms > 10 ms.
  const auto o = analyze(data("analyze_rm_above_bound.yaml"));
  EXPECT_EXIT_CODE(o, 1);
  EXPECT_TRUE(contains(o.out, "every C includes 1 µs of framework overhead per cycle")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "c"), "10.006 ms  CAN MISS: response time 10.006 ms > deadline 10 ms")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "b"), "3.002 ms  meets")) << o.out;
}

TEST_F(AnalyzeTest, RateMonotonicMissExitsOneAndSaysWhy) {
  const auto o = analyze(data("analyze_rm_infeasible.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 1);
  EXPECT_TRUE(contains(row_of(o.out, "fast"), "2 ms  meets")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "slow"), "8 ms  CAN MISS: response time 8 ms > deadline 7 ms")) << o.out;
  EXPECT_TRUE(contains(o.out, "configuration 'default': NOT feasible under rm: slow can miss\n")) << o.out;
  EXPECT_TRUE(contains(o.out, "/analyze_rm_infeasible.yaml: 1 of 1 configuration not feasible\n")) << o.out;
}

TEST_F(AnalyzeTest, EdfSchedulesWhatRateMonotonicCannot) {
  const auto o = analyze(data("analyze_edf_implicit.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "cpu 0: U = 0.971, bound 1 (EDF); every D >= T, so U <= 1 decides: passes\n")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "slow"), "<= 7 ms  meets")) << o.out;
}

TEST_F(AnalyzeTest, EdfConstrainedDeadlinesBothWays) {
  auto o = analyze(data("analyze_edf_constrained.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "some D < T: processor demand h(t) <= t checked up to L = 16 ms")) << o.out;
  EXPECT_TRUE(contains(o.out, "): passes\n")) << o.out;

  o = analyze(data("analyze_edf_constrained_miss.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 1);
  EXPECT_TRUE(contains(o.out, "fails: the jobs due in the first 6 ms need 7 ms\n")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "c"), "CAN MISS: the jobs due in the first 6 ms need 7 ms")) << o.out;
  EXPECT_TRUE(contains(o.out, "NOT feasible under edf: a, b, c can miss")) << o.out;
}

TEST_F(AnalyzeTest, DeadlineMonotonic) {
  const auto o = analyze(data("analyze_dm.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "(it holds only where D = T); response-time analysis decides")) << o.out;
  EXPECT_EQ(row_of(o.out, "a"), "  a     assigned  hard  3 ms  file  20 ms   5 ms      3 ms  meets") << o.out;
  EXPECT_EQ(row_of(o.out, "b"), "  b     assigned  hard  3 ms  file  15 ms   7 ms      6 ms  meets") << o.out;
  EXPECT_EQ(row_of(o.out, "c"), "  c     assigned  hard  4 ms  file  10 ms  10 ms     10 ms  meets") << o.out;
  EXPECT_EQ(row_of(o.out, "d"), "  d     assigned  hard  3 ms  file  20 ms  20 ms     20 ms  meets") << o.out;
}

TEST_F(AnalyzeTest, MufGuaranteesTheCriticalSet) {
  auto o = analyze(data("analyze_muf.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "critical set a, b: U = 0.800, bound 1 (EDF among critical tasks); every hard task fits"))
      << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "b"), "hard  3 ms  file  10 ms  10 ms  <= 10 ms  meets (critical)")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "c"),
                       "soft  2 ms  file   5 ms   5 ms         -  no guarantee: outside the "
                       "critical set"))
      << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "d"), "no guarantee")) << o.out;

  o = analyze(data("analyze_muf_unfit.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 1);
  EXPECT_TRUE(contains(row_of(o.out, "x"),
                       "CAN MISS: hard, but does not fit in the critical set: with it, "
                       "overloaded: U = 1.100 > 1"))
      << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "y"), "meets (critical)")) << o.out;
  EXPECT_TRUE(contains(o.out, "NOT feasible under muf: x can miss")) << o.out;
}

TEST_F(AnalyzeTest, TheAssignmentIsShownPerCpu) {
  // Worst fit, largest first: big (0.6) on CPU 0, beside pinned (0.5) on CPU 1 goes medium (0.4),
  // then small (0.3) on CPU 0: 0.9 and 0.9.
  const auto o = analyze(data("analyze_two_cpus.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 0);
  const auto cpu1 = o.out.find("cpu 1: ");
  ASSERT_NE(cpu1, std::string::npos) << o.out;
  EXPECT_LT(o.out.find("cpu 0: U = 0.900"), cpu1) << o.out;
  EXPECT_LT(o.out.find("  big "), cpu1);
  EXPECT_LT(o.out.find("  small "), cpu1);
  EXPECT_GT(o.out.find("  medium "), cpu1);
  EXPECT_GT(o.out.find("  pinned "), cpu1);
  EXPECT_TRUE(contains(row_of(o.out, "pinned"), "pinned    hard  5 ms")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "medium"), "assigned  hard  4 ms")) << o.out;
  EXPECT_TRUE(contains(o.out, "on cpus 0, 1;")) << o.out;
}

TEST_F(AnalyzeTest, AServerCountsItsBudgetAndOneJob) {
  const auto o = analyze(data("analyze_server.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "cpu 0: U = 0.800, Liu-Layland bound 0.828 for 2 tasks")) << o.out;
  EXPECT_EQ(row_of(o.out, "ctl"), "  ctl   assigned  hard         5 ms  file         10 ms  10 ms      8 ms  meets")
      << o.out;
  EXPECT_EQ(row_of(o.out, "cmd"), "  cmd   assigned  hard  2 ms + 1 ms  file         10 ms  10 ms      8 ms  meets")
      << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "log"), "aperiodic      -         -  background: aperiodic without a server"))
      << o.out;
}

TEST_F(AnalyzeTest, EveryConfigurationOrOne) {
  auto o = analyze(data("analyze_two_configs.yaml") + " --overhead 0ns");
  EXPECT_EXIT_CODE(o, 1);
  EXPECT_TRUE(contains(o.out, "configuration 'light': feasible under rm\n")) << o.out;
  EXPECT_TRUE(contains(o.out, "configuration 'heavy': NOT feasible under rm: slow can miss\n")) << o.out;
  EXPECT_TRUE(contains(o.out, "analyze_two_configs.yaml: 1 of 2 configurations not feasible\n")) << o.out;

  o = analyze(data("analyze_two_configs.yaml") + " --overhead 0ns --config light");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_FALSE(contains(o.out, "heavy")) << o.out;
  EXPECT_TRUE(contains(o.out, "analyze_two_configs.yaml: 1 configuration feasible\n")) << o.out;
}

TEST_F(AnalyzeTest, MeasuresTasksWithoutWcet) {
  const auto o = analyze(data("analyze_measured.yaml"));
  // Periods of 1 s and 2 s: even a cycle stretched by the machine's worst stall fits.
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(
      contains(o.out, "measured: C = 1.5 x the longest cycle, the least of 5 runs of 40 s on the virtual clock"))
      << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "slow"), " measured ")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "slower"), " measured ")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "slower"), "meets")) << o.out;
  EXPECT_FALSE(contains(row_of(o.out, "slow"), "  ?  ")) << o.out;  // a C was found
}

TEST_F(AnalyzeTest, WcetFromAProfile) {
  // slow 300 ms of 1 s, slower 900 ms of 2 s: U = 0.75, under the bound; R(slower) = 0.9 + 2 x 0.3.
  const std::string good = write("wcet.yaml",
                                 "# written by chimera profile\n"
                                 "subsystem: an_measured\n"
                                 "clock: real\n"
                                 "tasks:\n"
                                 "  slow: { wcet: 300ms, exec_max: 200ms, cycles: 10 }\n"
                                 "  slower: { wcet: 900ms }\n");
  auto o = analyze(data("analyze_measured.yaml") + " --overhead 0ns --wcet-from " + good);
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_FALSE(contains(o.out, "\nmeasured: ")) << o.out;  // nothing left to measure
  EXPECT_EQ(row_of(o.out, "slow"), "  slow    assigned  hard  300 ms  profile  1 s  1 s    300 ms  meets") << o.out;
  EXPECT_EQ(row_of(o.out, "slower"), "  slower  assigned  hard  900 ms  profile  2 s  2 s     1.5 s  meets") << o.out;

  // 1.5 s of 2 s for slower: U = 1.05, and harmonic periods miss only by overload.
  const std::string heavy =
      write("heavy.yaml", "subsystem: an_measured\ntasks:\n  slow: { wcet: 300ms }\n  slower: { wcet: 1500ms }\n");
  o = analyze(data("analyze_measured.yaml") + " --overhead 0ns --wcet-from " + heavy);
  EXPECT_EXIT_CODE(o, 1);
  EXPECT_TRUE(
      contains(row_of(o.out, "slower"),
               "-  CAN MISS: overloaded: it and the tasks at or above its priority need 1.050 of the processor"))
      << o.out;

  // A task the profile leaves out is measured.
  const std::string partial = write("partial.yaml", "subsystem: an_measured\ntasks:\n  slower: { wcet: 900ms }\n");
  o = analyze(data("analyze_measured.yaml") + " --wcet-from " + partial);
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "\nmeasured: C = 1.5 x")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "slow"), " measured ")) << o.out;
  EXPECT_TRUE(contains(row_of(o.out, "slower"), "900 ms  profile")) << o.out;
}

TEST_F(AnalyzeTest, BadProfilesExitTwoNamingFileLineAndKey) {
  const std::string bad = write("wcet.yaml",
                                "# written by chimera profile\n"
                                "subsystem: an_measured\n"
                                "clock: real\n"
                                "tasks:\n"
                                "  slow: { wcet: 35 us }\n");
  auto o = analyze(data("analyze_measured.yaml") + " --wcet-from " + bad);
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "wcet.yaml:5: tasks.slow.wcet: \"35 us\" is not a duration")) << o.err;
  EXPECT_EQ(o.out, "");

  const std::string other = write("other.yaml", "subsystem: fig4\ntasks:\n  slow: { wcet: 1ms }\n");
  o = analyze(data("analyze_measured.yaml") + " --wcet-from " + other);
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "other.yaml:1: subsystem: the profile is of subsystem fig4")) << o.err;

  const std::string stranger = write("stranger.yaml", "subsystem: an_measured\ntasks:\n  nosuch: { wcet: 1ms }\n");
  o = analyze(data("analyze_measured.yaml") + " --wcet-from " + stranger);
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "stranger.yaml:3: tasks.nosuch: no task named nosuch")) << o.err;

  o = analyze(data("analyze_measured.yaml") + " --wcet-from " + quoted(path("missing.yaml")));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "missing.yaml: cannot open the profile")) << o.err;
}

TEST_F(AnalyzeTest, InvalidInputExitsTwo) {
  auto o = analyze(data("bad_period.yaml"));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "bad_period.yaml:8: tasks[1].period")) << o.err;
  EXPECT_EQ(o.out, "");

  o = analyze(data("analyze_two_configs.yaml") + " --config nosuch");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "unknown configuration 'nosuch'")) << o.err;

  // An illegal configuration cannot run, so it is not analysed.
  o = analyze(data("illegal.yaml"));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "illegal.yaml: configuration 'no_traj': rule 2: theta_d")) << o.err;
  EXPECT_TRUE(contains(o.err, "only legal configurations can be analysed")) << o.err;
  EXPECT_EQ(o.out, "");

  for (const char* args : {" --overhead 1 us", " --overhead -1ms", " --overhead soon", " --bogus"}) {
    o = analyze(data("analyze_dm.yaml") + args);
    EXPECT_EXIT_CODE(o, 2);
    EXPECT_FALSE(o.err.empty()) << args;
  }
  o = chimera("analyze");
  EXPECT_EXIT_CODE(o, 2);
}

}  // namespace
}  // namespace chimera::test
