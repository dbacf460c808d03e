// The profile file: what chimera profile writes reads back the same; bad input names file, line
// and key.

#include "chimera/analysis/wcet_profile.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace chimera::analysis {
namespace {

constexpr const char* kExample = R"(# written by chimera profile
subsystem: fig4
clock: real
tasks:
  traj: { wcet: 35us, exec_max: 35us, exec_p99: 20us, cycles: 10000 }
  pid:
    wcet: 2.5ms
)";

TEST(WcetProfile, ReadsTheDocumentedFormat) {
  auto p = read_wcet_profile_text(kExample, "wcet.yaml");
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_EQ(p->file, "wcet.yaml");
  EXPECT_EQ(p->subsystem, "fig4");
  EXPECT_EQ(p->clock, "real");
  ASSERT_EQ(p->tasks.size(), 2U);
  const ProfileEntry* traj = p->find("traj");
  ASSERT_NE(traj, nullptr);
  EXPECT_EQ(traj->wcet_ns, 35'000);
  EXPECT_EQ(traj->exec_max_ns, 35'000);
  EXPECT_EQ(traj->exec_p99_ns, 20'000);
  EXPECT_EQ(traj->cycles, 10'000U);
  EXPECT_EQ(traj->line, 5);
  const ProfileEntry* pid = p->find("pid");
  ASSERT_NE(pid, nullptr);
  EXPECT_EQ(pid->wcet_ns, 2'500'000);
  EXPECT_FALSE(pid->exec_max_ns);
  EXPECT_FALSE(pid->cycles);
  EXPECT_EQ(p->find("robot"), nullptr);
}

TEST(WcetProfile, WriteThenReadGivesTheSameNumbers) {
  WcetProfile p;
  p.subsystem = "arm";
  p.clock = "virtual";
  p.tasks.push_back(measured_entry("pid", 1'234'567, 1000, 1.5));  // wcet 1851850.5 -> 1851851 ns, exact
  p.tasks.push_back(measured_entry("robot", 0, 0, 1.0, 20'000));
  p.tasks.back().wcet_ns = 35'000;
  p.tasks.back().exec_max_ns.reset();
  p.tasks.back().cycles.reset();
  p.tasks.push_back(measured_entry("slow", 1'999'999'999, 7, 1.0));
  p.tasks.back().wcet_ns = 2'000'000'000;
  const std::string text = format_wcet_profile(p);
  EXPECT_EQ(text,
            "# written by chimera profile: wcet is the budget chimera analyze --wcet-from uses\n"
            "subsystem: arm\n"
            "clock: virtual\n"
            "tasks:\n"
            "  pid: { wcet: 1851.851us, exec_max: 1234.567us, cycles: 1000 }\n"
            "  robot: { wcet: 35us, exec_p99: 20us }\n"
            "  slow: { wcet: 2s, exec_max: 1999999.999us, cycles: 7 }\n");
  auto back = read_wcet_profile_text(text, "p.yaml");
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->tasks.size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back->tasks[i].task, p.tasks[i].task);
    EXPECT_EQ(back->tasks[i].wcet_ns, p.tasks[i].wcet_ns);
    EXPECT_EQ(back->tasks[i].exec_max_ns, p.tasks[i].exec_max_ns);
    EXPECT_EQ(back->tasks[i].exec_p99_ns, p.tasks[i].exec_p99_ns);
    EXPECT_EQ(back->tasks[i].cycles, p.tasks[i].cycles);
  }
}

TEST(WcetProfile, AnEmptyProfileIsWrittenAndReadBack) {
  WcetProfile p;
  p.subsystem = "s";
  auto back = read_wcet_profile_text(format_wcet_profile(p), "p.yaml");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->tasks.empty());
  EXPECT_EQ(back->clock, "");
}

TEST(WcetProfile, WritesAndReadsAFile) {
  const std::string path = (std::filesystem::temp_directory_path() / "chimera_wcet_profile_test.yaml").string();
  WcetProfile p;
  p.subsystem = "s";
  p.tasks.push_back(measured_entry("a", 100, 5, 2.0));
  ASSERT_TRUE(write_wcet_profile_file(path, p));
  auto back = read_wcet_profile_file(path);
  std::remove(path.c_str());
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->file, path);
  EXPECT_EQ(back->tasks.at(0).wcet_ns, 200);
  EXPECT_FALSE(write_wcet_profile_file("/nonexistent_dir/p.yaml", p));
  const auto missing = read_wcet_profile_file("/nonexistent_dir/p.yaml");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message.rfind("/nonexistent_dir/p.yaml: cannot open the profile", 0), 0U);
}

// A profile is read as a subsystem file is: a FIFO with no writer would block analyze forever,
// /dev/zero would be read without end.
TEST(WcetProfile, OnlyARegularFileOfBoundedSizeIsRead) {
  const std::string fifo =
      (std::filesystem::temp_directory_path() / ("chimera_wcet_profile_fifo_" + std::to_string(::getpid()))).string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto from_fifo = read_wcet_profile_file(fifo);
  std::remove(fifo.c_str());
  ASSERT_FALSE(from_fifo);
  EXPECT_EQ(from_fifo.error().message, fifo + ": is a FIFO, not a profile (only regular files are read)");
  const auto from_zero = read_wcet_profile_file("/dev/zero");
  ASSERT_FALSE(from_zero);
  EXPECT_EQ(from_zero.error().message, "/dev/zero: is a character device, not a profile (only regular files are read)");
}

std::string error_of(const std::string& text) {
  auto p = read_wcet_profile_text(text, "wcet.yaml");
  return p ? std::string("(no error)") : p.error().message;
}

TEST(WcetProfile, BadInputNamesFileLineAndKey) {
  const std::string head = "subsystem: fig4\nclock: real\ntasks:\n";
  EXPECT_EQ(error_of(head + "  a: { wcet: 35 us }\n"),
            "wcet.yaml:4: tasks.a.wcet: \"35 us\" is not a duration (use ns, us, ms or s, e.g. 10ms)");
  EXPECT_EQ(error_of(head + "  a: { wcet: 0us }\n"), "wcet.yaml:4: tasks.a.wcet: must be greater than zero");
  EXPECT_EQ(error_of(head + "  a: { exec_max: 3us }\n"),
            "wcet.yaml:4: tasks.a.wcet: missing (the budget analysis uses, e.g. wcet: 35us)");
  EXPECT_EQ(error_of(head + "  a: { wcet: 3us, wcte: 4us }\n"),
            "wcet.yaml:4: tasks.a.wcte: unknown key (known: wcet, exec_max, exec_p99, cycles)");
  EXPECT_EQ(error_of(head + "  a: { wcet: 3us, cycles: -1 }\n"),
            "wcet.yaml:4: tasks.a.cycles: \"-1\" is not a count (a whole number >= 0)");
  EXPECT_EQ(error_of(head + "  a: { wcet: 3us }\n  a: { wcet: 4us }\n"),
            "wcet.yaml:5: tasks.a: written twice (first at line 4)");
  EXPECT_EQ(error_of(head + "  a: 35us\n"),
            "wcet.yaml:4: tasks.a: a task's figures must be a mapping of keys, not \"35us\"");
  EXPECT_EQ(error_of("subsystem: fig4\nclock: wall\ntasks: {}\n"),
            "wcet.yaml:2: clock: \"wall\" is not a clock (use real or virtual)");
  EXPECT_EQ(error_of("clock: real\ntasks: {}\n"),
            "wcet.yaml:1: subsystem: missing (the subsystem the profile was measured on)");
  EXPECT_EQ(error_of("subsystem: s\ntasks: {}\nextra: 1\n"),
            "wcet.yaml:3: extra: unknown key (known: subsystem, clock, tasks)");
  EXPECT_EQ(error_of("subsystem: s\ntasks: [a]\n"), "wcet.yaml:2: tasks: tasks must be a mapping, not a list");
  EXPECT_EQ(error_of("subsystem: s\ntasks: {a: {wcet: [1\n"),
            "wcet.yaml:3: YAML syntax error: end of sequence flow not found");
  EXPECT_EQ(error_of(""),
            "wcet.yaml:1: a profile is one mapping: subsystem:, clock: and tasks: (written by chimera profile)");
}

TEST(WcetProfile, MatchesOnlyItsOwnSubsystem) {
  auto p = read_wcet_profile_text(kExample, "wcet.yaml");
  ASSERT_TRUE(p);
  SubsystemSpec spec;
  spec.name = "fig4";
  spec.file = "fig4.yaml";
  spec.tasks.resize(2);
  spec.tasks[0].name = "traj";
  spec.tasks[1].name = "pid";
  EXPECT_TRUE(check_profile_matches(*p, spec));

  spec.tasks.pop_back();
  auto r = check_profile_matches(*p, spec);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "wcet.yaml:6: tasks.pid: no task named pid in fig4.yaml (tasks: traj)");

  spec.name = "other";
  r = check_profile_matches(*p, spec);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message,
            "wcet.yaml:2: subsystem: the profile is of subsystem fig4, but fig4.yaml describes subsystem other");
}

TEST(MeasuredEntry, TheMarginRoundsUp) {
  const auto e = measured_entry("a", 1001, 3, 1.5);
  EXPECT_EQ(e.wcet_ns, 1502);
  EXPECT_EQ(e.exec_max_ns, 1001);
  EXPECT_EQ(e.cycles, 3U);
  EXPECT_EQ(measured_entry("b", 0, 1, 1.5).wcet_ns, 1);  // never a zero (unknown) budget
}

}  // namespace
}  // namespace chimera::analysis
