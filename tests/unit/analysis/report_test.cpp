// What chimera analyze prints for a configuration: headings, one row per task, the verdict.

#include "chimera/analysis/report.hpp"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace chimera::analysis {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TaskModel task(const char* name, std::int64_t c, std::int64_t t, int file_index, int cpu = -1) {
  return TaskModel{.name = name,
                   .wcet_ns = c,
                   .period_ns = t,
                   .cpu = cpu,
                   .file_index = file_index,
                   .wcet_source = c > 0 ? WcetSource::kFile : WcetSource::kUnknown};
}

std::string report(const std::vector<TaskModel>& tasks, const std::vector<int>& cpu_of, SchedulerKind scheduler,
                   std::string note = {}) {
  const AnalysisOptions options{.overhead_ns = 0};
  const std::vector<int> cpus{0, 1};
  const auto result = analyse_configuration(tasks, cpu_of, cpus, scheduler, options);
  return format_report(ReportContext{"f.yaml", "main", scheduler, options, std::move(note)}, tasks, result);
}

TEST(Report, OneTablePerCpuAndTheVerdict) {
  std::vector<TaskModel> tasks{task("slow", 4 * kMs, 7 * kMs, 0), task("fast", 2 * kMs, 5 * kMs, 1, 0),
                               task("other", 1 * kMs, 10 * kMs, 2), task("bg", 1 * kMs, 0, 3)};
  tasks[2].wcet_source = WcetSource::kMeasured;
  tasks[2].hard = false;
  const std::string text = report(tasks, {0, 0, 1, 1}, SchedulerKind::kRm, "measured: a note");
  EXPECT_EQ(text,
            "f.yaml: configuration 'main', 4 tasks under rm on cpus 0, 1; every C includes 0 ns of framework "
            "overhead per cycle\n"
            "measured: a note\n"
            "cpu 0: U = 0.971, Liu-Layland bound 0.828 for 2 tasks: above the bound; response-time analysis decides\n"
            "  task  placed    crit     C  from     T     D  response  verdict\n"
            "  fast  pinned    hard  2 ms  file  5 ms  5 ms      2 ms  meets\n"
            "  slow  assigned  hard  4 ms  file  7 ms  7 ms      8 ms  CAN MISS: response time 8 ms > deadline 7 ms\n"
            "cpu 1: U = 0.100, Liu-Layland bound 1.000 for 1 task: under the bound, feasible; response times below\n"
            "  task   placed    crit     C  from              T      D  response  verdict\n"
            "  other  assigned  soft  1 ms  measured      10 ms  10 ms      1 ms  meets\n"
            "  bg     assigned  hard  1 ms  file      aperiodic      -         -  background: aperiodic without a "
            "server: runs when nothing else does\n"
            "configuration 'main': NOT feasible under rm: slow can miss\n");
}

TEST(Report, EdfAndMufHeadings) {
  const std::vector<TaskModel> tasks{task("a", 2 * kMs, 5 * kMs, 0), task("b", 4 * kMs, 7 * kMs, 1)};
  const std::string edf = report(tasks, {0, 0}, SchedulerKind::kEdf);
  EXPECT_NE(edf.find("cpu 0: U = 0.971, bound 1 (EDF); every D >= T, so U <= 1 decides: passes\n"), std::string::npos)
      << edf;
  EXPECT_NE(edf.find("<= 7 ms  meets\n"), std::string::npos) << edf;
  EXPECT_NE(edf.find("cpu 1: no tasks\n"), std::string::npos) << edf;
  EXPECT_NE(edf.find("configuration 'main': feasible under edf\n"), std::string::npos) << edf;

  const std::string muf = report(tasks, {0, 0}, SchedulerKind::kMuf);
  EXPECT_NE(muf.find("cpu 0: U = 0.971; critical set a, b: U = 0.971, bound 1 (EDF among critical tasks); every hard "
                     "task fits\n"),
            std::string::npos)
      << muf;
  EXPECT_NE(muf.find("meets (critical)"), std::string::npos) << muf;
}

TEST(Report, UnknownExecutionTimeAndServers) {
  std::vector<TaskModel> tasks{task("u", 0, 10 * kMs, 0)};
  tasks.push_back(TaskModel{.name = "srv",
                            .wcet_ns = 2 * kMs,
                            .job_wcet_ns = kMs,
                            .period_ns = 20 * kMs,
                            .server = true,
                            .file_index = 1,
                            .wcet_source = WcetSource::kFile});
  const std::string text = report(tasks, {0, 1}, SchedulerKind::kRm);
  EXPECT_NE(text.find("cpu 0: U = at least 0.000, Liu-Layland bound 1.000 for 1 task: above the bound; response-time "
                      "analysis decides\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  u     assigned  hard  ?  unknown  10 ms  10 ms         -  CAN MISS: execution time unknown"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  srv   assigned  hard  2 ms + 1 ms  file  20 ms  20 ms      3 ms  meets\n"), std::string::npos)
      << text;
  EXPECT_EQ(tasks_that_can_miss(tasks, analyse_configuration(tasks, std::vector<int>{0, 1}, std::vector<int>{0, 1},
                                                             SchedulerKind::kRm, AnalysisOptions{})),
            (std::vector<std::string>{"u"}));
}

}  // namespace
}  // namespace chimera::analysis
