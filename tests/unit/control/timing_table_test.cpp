#include "chimera/control/timing_table.hpp"

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "chimera/control/stats_json.hpp"
#include "chimera/core/text_table.hpp"
#include "support/json_text.hpp"

namespace chimera {
namespace {

std::vector<TaskSnapshot> sample() {
  TaskSnapshot pid;
  pid.name = "pid";
  pid.module = "pid_joint";
  pid.state = TaskState::kOn;
  pid.period_ns = 1'000'000;
  pid.cpu = 1;
  pid.stats.cycles = 2000;
  pid.stats.missed = 3;
  pid.stats.exec_mean_ns = 12'345;
  pid.stats.exec_max_ns = 250'000;
  pid.stats.latency_p50_ns = 800;
  pid.stats.latency_p99_ns = 40'000;
  pid.stats.latency_max_ns = 1'500'000;
  TaskSnapshot traj;
  traj.name = "traj";
  traj.module = "joint_traj_gen";
  traj.state = TaskState::kNotCreated;
  traj.period_ns = 10'000'000;
  return {pid, traj};
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

TEST(TextTable, AlignsByCodePoints) {
  TextTable t({{"a", TextTable::Align::kLeft}, {"b", TextTable::Align::kRight}});
  t.add_row({"x", "1 µs"});
  t.add_row({"long", "10 ms"});
  EXPECT_EQ(t.render(),
            "a         b\n"
            "x      1 µs\n"
            "long  10 ms\n");
  EXPECT_EQ(display_width("µs"), 2U);
}

TEST(StatusTable, OneRowPerTask) {
  const auto text = status_table(sample());
  const auto lines = lines_of(text);
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_EQ(lines[0], "task  module          state        cpu  period  cycles  missed");
  EXPECT_EQ(lines[1], "pid   pid_joint       ON             1    1 ms    2000       3");
  EXPECT_EQ(lines[2], "traj  joint_traj_gen  NOT-CREATED    0   10 ms       0       0");
}

TEST(StatusTable, ShowsTheLastErrorWhenThereIsOne) {
  auto tasks = sample();
  tasks[0].last_error = "ERROR: operator intervention required (clear): joint limit";
  const auto text = status_table(tasks);
  EXPECT_NE(lines_of(text)[0].find("last error"), std::string::npos);
  EXPECT_NE(text.find("joint limit"), std::string::npos);
}

TEST(StatusTable, TellsAPastErrorFromTheCurrentState) {
  auto tasks = sample();
  tasks[0].last_error = "ERROR: operator intervention required (clear): joint limit";
  tasks[0].last_error_ns = 1'250'000'000;
  tasks[0].state = TaskState::kError;
  EXPECT_NE(status_table(tasks).find("  ERROR: operator intervention required (clear): joint limit\n"),
            std::string::npos)
      << status_table(tasks);

  // After clear and on: the state says ON, and the error says it was cleared, and when.
  tasks[0].state = TaskState::kOn;
  tasks[0].error_ended_by = Signal::kClear;
  tasks[0].error_ended_ns = 1'400'000'000;
  const auto cleared = status_table(tasks);
  EXPECT_NE(cleared.find("cleared at 1.400 s, was: ERROR: operator intervention required (clear): joint limit\n"),
            std::string::npos)
      << cleared;

  tasks[0].error_ended_by = Signal::kKill;
  EXPECT_NE(status_table(tasks).find("killed at 1.400 s, was: "), std::string::npos) << status_table(tasks);

  // A failure that error() recovered from never was the task's state.
  tasks[0].error_ended_by.reset();
  tasks[0].last_error = "cycle failed: joint limit";
  EXPECT_NE(status_table(tasks).find("past, at 1.250 s: cycle failed: joint limit\n"), std::string::npos)
      << status_table(tasks);
}

TEST(TimingTable, HumanUnitsAndDashesForTasksThatNeverRan) {
  const auto lines = lines_of(timing_table(sample()));
  ASSERT_EQ(lines.size(), 3U);
  for (const char* header : {"task", "module", "state", "period", "cycles", "missed", "exec mean", "exec max",
                             "latency p50", "latency p99", "latency max"})
    EXPECT_NE(lines[0].find(header), std::string::npos) << header;
  for (const char* figure : {"12.3 µs", "250.0 µs", "800 ns", "40.0 µs", "1.50 ms"})
    EXPECT_NE(lines[1].find(figure), std::string::npos) << figure;
  EXPECT_EQ(lines[2].substr(lines[2].size() - 1), "-");
  // Every line has the same width: the columns line up.
  EXPECT_EQ(display_width(lines[0]), display_width(lines[1]));
}

TEST(TimingTable, SimulatedExecutionTimesSaySo) {
  auto tasks = sample();
  EXPECT_EQ(timing_table(tasks).find("(simulated)"), std::string::npos);
  tasks[0].stats.exec_simulated = true;
  const auto lines = lines_of(timing_table(tasks));
  EXPECT_NE(lines[0].find("exec mean (simulated)"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("exec max (simulated)"), std::string::npos) << lines[0];
  EXPECT_EQ(display_width(lines[0]), display_width(lines[1]));
}

TEST(StatsJson, SaysWhichClockExecutionTimesAreIn) {
  auto tasks = sample();
  tasks[0].stats.host_exec_mean_ns = 900;
  tasks[0].stats.host_exec_max_ns = 1200;
  auto doc = test::parse_json(stats_json(tasks, ClockKind::kVirtual, 0));
  EXPECT_EQ(doc.at("exec_clock"), "virtual");
  EXPECT_EQ(doc.at("tasks").at("pid").at("exec_clock"), "virtual");
  EXPECT_EQ(doc.at("tasks").at("pid").at("host_exec_ns").at("mean"), 900);
  EXPECT_EQ(doc.at("tasks").at("pid").at("host_exec_ns").at("max"), 1200);
  EXPECT_EQ(doc.at("tasks").at("pid").at("exec_ns").at("max"), 250'000);  // the existing key stays
  doc = test::parse_json(stats_json(tasks, ClockKind::kReal, 0));
  EXPECT_EQ(doc.at("exec_clock"), "host");
  EXPECT_EQ(doc.at("tasks").at("traj").at("exec_clock"), "host");
}

TEST(TimingTable, RtViolationsColumnWithTheCheckOrWhenAnyTaskHasSome) {
  EXPECT_EQ(timing_table(sample()).find("rt violations"), std::string::npos);
  // With --rt-check, zeros are the answer: the column shows.
  const auto checked = lines_of(timing_table(sample(), true));
  EXPECT_NE(checked[0].find("rt violations"), std::string::npos);
  auto tasks = sample();
  tasks[0].stats.rt_violations = 2000;
  const auto lines = lines_of(timing_table(tasks));
  ASSERT_NE(lines[0].find("rt violations"), std::string::npos);
  EXPECT_NE(lines[1].find("2000"), std::string::npos);
  EXPECT_EQ(display_width(lines[0]), display_width(lines[1]));
}

TEST(StatsJson, RtViolationsPerTaskAndWhetherTheyWereCounted) {
  auto tasks = sample();
  tasks[0].stats.rt_violations = 7;
  const auto doc = test::parse_json(stats_json(tasks, ClockKind::kVirtual, 0, true));
  EXPECT_EQ(doc.at("rt_check"), true);
  EXPECT_EQ(doc.at("tasks").at("pid").at("rt_violations"), 7);
  EXPECT_EQ(doc.at("tasks").at("traj").at("rt_violations"), 0);
  EXPECT_EQ(test::parse_json(stats_json(tasks, ClockKind::kVirtual, 0)).at("rt_check"), false);
}

TEST(StatsJson, HasTheContractKeys) {
  const auto doc = test::parse_json(stats_json(sample(), ClockKind::kVirtual, 0));
  EXPECT_EQ(doc.at("clock"), "virtual");
  EXPECT_EQ(doc.at("switches"), 0);
  const auto& pid = doc.at("tasks").at("pid");
  EXPECT_EQ(pid.at("state"), "ON");
  EXPECT_EQ(pid.at("cycles"), 2000);
  EXPECT_EQ(pid.at("missed"), 3);
  EXPECT_EQ(pid.at("exec_ns").at("mean"), 12'345);
  EXPECT_EQ(pid.at("exec_ns").at("max"), 250'000);
  EXPECT_EQ(pid.at("latency_ns").at("p50"), 800);
  EXPECT_EQ(pid.at("latency_ns").at("p99"), 40'000);
  EXPECT_EQ(pid.at("latency_ns").at("max"), 1'500'000);
  EXPECT_EQ(doc.at("tasks").at("traj").at("state"), "NOT-CREATED");
  EXPECT_EQ(test::parse_json(stats_json({}, ClockKind::kReal, 0)).at("clock"), "real");
}

TEST(StatsJson, UnwritablePathIsAnError) {
  auto r = write_stats_json("/nonexistent-dir/stats.json", sample(), ClockKind::kReal, 0);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("/nonexistent-dir/stats.json"), std::string::npos);
}

TEST(StatsJson, CompactIsTheSameDocumentOnOneLine) {
  auto tasks = sample();
  tasks[0].stats.latency_histogram = {{1000, 5}, {2000, 7}, {4000, 1}};
  const std::string indented = stats_json(tasks, ClockKind::kReal, 4);
  const std::string compact = stats_json(tasks, ClockKind::kReal, 4, false, JsonLayout::kCompact);
  EXPECT_EQ(test::parse_json(compact), test::parse_json(indented));
  EXPECT_EQ(compact.find('\n'), std::string::npos);
  EXPECT_LT(compact.size(), indented.size());
}

}  // namespace
}  // namespace chimera
