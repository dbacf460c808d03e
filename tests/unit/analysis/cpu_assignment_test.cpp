// CPU assignment: pinned tasks stay, the others worst-fit decreasing with a schedulability check,
// unknown shares spread evenly.

#include "chimera/analysis/cpu_assignment.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace chimera::analysis {
namespace {

constexpr AnalysisOptions kNoOverhead{.overhead_ns = 0};

TaskModel task(const char* name, std::int64_t c, std::int64_t t, int file_index, int cpu = -1) {
  return TaskModel{.name = name, .wcet_ns = c, .period_ns = t, .cpu = cpu, .file_index = file_index};
}

TEST(AssignCpus, WorstFitDecreasingBalancesTheLoad) {
  // Utilisations 0.3, 0.6, 0.4, 0.5 (file order). Largest first, each on the least-loaded CPU:
  // 0.6 -> 0, 0.5 -> 1, 0.4 -> 1 (0.5 < 0.6), 0.3 -> 0: 0.9 and 0.9. First fit would have
  // filled CPU 0 to 1.0 and left 0.8 on CPU 1.
  const std::vector<TaskModel> tasks{task("a", 3, 10, 0), task("b", 6, 10, 1), task("c", 4, 10, 2),
                                     task("d", 5, 10, 3)};
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kEdf, kNoOverhead),
            (std::vector<int>{0, 0, 1, 1}));
}

TEST(AssignCpus, PinnedTasksStayAndCountAsLoad) {
  const std::vector<TaskModel> tasks{task("pinned", 5, 10, 0, 1), task("x", 4, 10, 1), task("y", 3, 10, 2),
                                     task("far", 1, 10, 3, 7)};
  // x (0.4) -> CPU 0 (empty), y (0.3) -> CPU 0 (0.4 < 0.5); `far` keeps a CPU the list lacks.
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kRm, kNoOverhead),
            (std::vector<int>{1, 0, 0, 7}));
}

TEST(AssignCpus, SkipsALessLoadedCpuWhereTheTaskWouldMiss) {
  // CPU 1 holds (34, 70), U = 0.486; CPU 0 holds (50, 100), U = 0.5. The new (100, 200) would
  // miss on CPU 1 under rm (R: 134 -> 168 -> 202 > 200) but fits CPU 0 exactly (harmonic, U = 1).
  const std::vector<TaskModel> tasks{task("y", 50, 100, 0, 0), task("x", 34, 70, 1, 1), task("z", 100, 200, 2)};
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kRm, kNoOverhead), (std::vector<int>{0, 1, 0}));
}

TEST(AssignCpus, ShortDeadlinesUnderRateMonotonicGetTheExactCheck) {
  // urgent (1, T 200, D 2) has a density of only 0.5, yet under rm the pinned (2, 10) on the
  // less-loaded CPU 0 outranks it: 1 + 2 = 3 > 2. On CPU 1 it outranks the pinned (100, 400).
  // Under dm it outranks both, and CPU 0 is fine.
  std::vector<TaskModel> tasks{task("ctl", 2, 10, 0, 0), task("slow", 100, 400, 1, 1), task("urgent", 1, 200, 2)};
  tasks[2].deadline_ns = 2;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kRm, kNoOverhead), (std::vector<int>{0, 1, 1}));
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kDm, kNoOverhead), (std::vector<int>{0, 1, 0}));
}

TEST(AssignCpus, NowhereFeasibleGoesToTheLeastLoaded) {
  const std::vector<TaskModel> tasks{task("a", 9, 10, 0), task("b", 8, 10, 1), task("c", 5, 10, 2)};
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kEdf, kNoOverhead), (std::vector<int>{0, 1, 1}));
}

TEST(AssignCpus, UnknownExecutionTimesAreSpreadEvenly) {
  std::vector<TaskModel> tasks(5);
  for (int i = 0; i < 5; ++i) tasks[i] = task("u", 0, 10 + i, i);
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kMuf), (std::vector<int>{0, 1, 0, 1, 0}));
  // Pinned on CPU 0: the next goes to CPU 1.
  tasks[0].cpu = 0;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kMuf), (std::vector<int>{0, 1, 0, 1, 0}));
  // Pinned on CPU 1: the next goes to CPU 0, then a tie of one each goes to the lower number.
  tasks[0].cpu = 1;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kMuf), (std::vector<int>{1, 0, 0, 1, 0}));
}

TEST(AssignCpus, UnknownSharesPreferTheLessLoadedCpuOnATie) {
  // A known 0.8 goes on CPU 0; the first unknown then on CPU 1, the second on CPU 0 (fewest
  // unknowns first), then background tasks the same way.
  const std::vector<TaskModel> tasks{task("k", 8, 10, 0), task("u1", 0, 10, 1), task("u2", 0, 20, 2),
                                     task("bg", 1, 0, 3)};
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kRm, kNoOverhead),
            (std::vector<int>{0, 1, 0, 1}));
}

TEST(AssignCpus, OrderOfTheCpuListDoesNotMatter) {
  const std::vector<TaskModel> tasks{task("a", 3, 10, 0), task("b", 6, 10, 1), task("c", 4, 10, 2)};
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{3, 1}, SchedulerKind::kEdf, kNoOverhead),
            assign_cpus(tasks, std::vector<int>{1, 3}, SchedulerKind::kEdf, kNoOverhead));
  // b (0.6) on the lower number, c (0.4) on the other, a (0.3) where c is.
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{3, 1}, SchedulerKind::kEdf, kNoOverhead), (std::vector<int>{3, 1, 3}));
}

TEST(AssignCpus, NoCpusLeavesUnpinnedTasksUnassigned) {
  const std::vector<TaskModel> tasks{task("a", 3, 10, 0), task("b", 6, 10, 1, 0)};
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{}, SchedulerKind::kRm), (std::vector<int>{-1, 0}));
}

TEST(AssignSubsystemCpus, EveryTaskOfTheFileFromItsWcetAndCpu) {
  // Three tasks in two configurations: all are placed, in file order, as assign_cpus() would.
  SubsystemSpec spec;
  spec.scheduler = SchedulerKind::kEdf;
  for (const char* name : {"a", "b", "c"}) {
    TaskSpec t;
    t.name = name;
    t.period_ns = 10'000'000;
    t.deadline_ns = 10'000'000;
    spec.tasks.push_back(t);
  }
  spec.tasks[0].wcet_ns = 6'000'000;
  spec.tasks[1].wcet_ns = 3'000'000;
  spec.tasks[2].cpu = 0;  // unknown C, pinned
  spec.configurations.push_back(ConfigurationSpec{"one", {"a"}, {}});
  spec.configurations.push_back(ConfigurationSpec{"two", {"b", "c"}, {}});
  const std::vector<int> cpus{0, 1};
  const ReleaseOrder order{.rank = {0, 0, 0}, .predecessors = {{}, {}, {}}, .chain = {0, 1, 2}};  // no data flow
  EXPECT_EQ(assign_subsystem_cpus(spec, order, cpus), (std::vector<int>{0, 1, 0}));
}

// Figure 4 with the PID in a module process of its own, C unknown: the loop traj -> pid -> robot
// (and the monitor fed by it) is one chain, placed as one part per process. On one CPU each
// hand-over between processes costs two context switches a release; across CPUs the consumer
// spins for a producer running the release. The main process's part on CPU 0, the PID on CPU 1.
TEST(AssignSubsystemCpus, AChainAcrossProcessesIsPlacedAsOnePartPerProcess) {
  SubsystemSpec spec;
  spec.scheduler = SchedulerKind::kRm;
  for (const char* name : {"traj", "pid", "robot", "monitor"}) {
    TaskSpec t;
    t.name = name;
    t.period_ns = 1'000'000;
    spec.tasks.push_back(t);
  }
  const std::vector<int> cpus{0, 1};
  const ReleaseOrder order{.rank = {0, 1, 2, 3}, .predecessors = {{}, {0}, {1}, {0, 2}}, .chain = {0, 0, 0, 0}};
  EXPECT_EQ(assign_subsystem_cpus(spec, order, cpus), (std::vector<int>{0, 0, 0, 0})) << "all in one: one CPU";
  spec.tasks[1].process = "control";
  EXPECT_EQ(assign_subsystem_cpus(spec, order, cpus), (std::vector<int>{0, 1, 0, 0}));
  // Two parts in one module process stay together: robot and monitor apart from traj and pid.
  spec.tasks[1].process = kMainProcess;
  spec.tasks[2].process = "arm";
  spec.tasks[3].process = "arm";
  EXPECT_EQ(assign_subsystem_cpus(spec, order, cpus), (std::vector<int>{0, 0, 1, 1}));
}

// The chain: Figure 4 with a filter and a limiter in its loop, traj -> filter -> pid ->
// limit -> robot, all at 1 ms, C unknown. Spread task by task they went 0/1/0/1/0, and every
// consumer waited for its producer on the other CPU at every release.
TEST(AssignCpus, AChainOfUnknownExecutionTimesGoesWholeOnOneCpu) {
  std::vector<TaskModel> tasks;
  for (int i = 0; i < 5; ++i) {
    tasks.push_back(task("link", 0, 1'000'000, i));
    tasks.back().chain = 0;
  }
  tasks.push_back(task("logger", 0, 10'000'000, 5));  // another period: a chain of its own
  tasks.back().chain = 5;
  tasks.push_back(task("monitor", 0, 1'000'000, 6));  // same period, but fed by nobody of it
  tasks.back().chain = 6;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kRm), (std::vector<int>{0, 0, 0, 0, 0, 1, 1}));
  // Without chains (each task its own), the old spread: what the issue measured.
  for (auto& t : tasks) t.chain = -1;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kRm), (std::vector<int>{0, 1, 0, 1, 0, 0, 1}));
}

TEST(AssignCpus, AChainFollowsItsPinnedTask) {
  std::vector<TaskModel> tasks{task("a", 0, 10, 0), task("b", 0, 10, 1, 1), task("c", 0, 10, 2)};
  for (auto& t : tasks) t.chain = 0;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kEdf), (std::vector<int>{1, 1, 1}));
  // Known C too: the pinned CPU is tried first, although CPU 0 is emptier.
  for (auto& t : tasks) t.wcet_ns = 2;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kEdf, kNoOverhead), (std::vector<int>{1, 1, 1}));
}

TEST(AssignCpus, AChainOfKnownExecutionTimesGoesWholeWhereItFits) {
  // A chain of 0.3 + 0.3 and a lone 0.5: the chain (0.6) goes first, whole, on CPU 0; the 0.5 on
  // CPU 1. Task by task it would have been 0.5 | 0.3 and then 0.3 on CPU 1: the chain split.
  std::vector<TaskModel> tasks{task("p", 3, 10, 0), task("q", 5, 10, 1), task("c", 3, 10, 2)};
  tasks[0].chain = tasks[2].chain = 0;
  tasks[1].chain = 1;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kEdf, kNoOverhead), (std::vector<int>{0, 1, 0}));
}

TEST(AssignCpus, AChainThatFitsNowhereWholeIsSplit) {
  // 0.6 + 0.6 fits no CPU: the two go on different CPUs, and analysis counts the wait.
  std::vector<TaskModel> tasks{task("p", 6, 10, 0), task("c", 6, 10, 1)};
  tasks[0].chain = tasks[1].chain = 0;
  EXPECT_EQ(assign_cpus(tasks, std::vector<int>{0, 1}, SchedulerKind::kEdf, kNoOverhead), (std::vector<int>{0, 1}));
}

TEST(AllowedCpus, TheFilesListOrEveryOnlineCpu) {
  SubsystemSpec spec;
  EXPECT_EQ(allowed_cpus(spec, 3), (std::vector<int>{0, 1, 2}));
  spec.cpus = {2, 5};
  EXPECT_EQ(allowed_cpus(spec, 3), (std::vector<int>{2, 5}));
}

}  // namespace
}  // namespace chimera::analysis
