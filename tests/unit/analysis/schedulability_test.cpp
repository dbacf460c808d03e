// One CPU's verdict under each scheduler, and a configuration's over several CPUs.

#include "chimera/analysis/schedulability.hpp"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace chimera::analysis {
namespace {

constexpr AnalysisOptions kNoOverhead{.overhead_ns = 0};

TaskModel task(const char* name, std::int64_t c, std::int64_t t, int file_index, std::int64_t d = 0, bool hard = true) {
  return TaskModel{
      .name = name, .wcet_ns = c, .period_ns = t, .deadline_ns = d, .hard = hard, .file_index = file_index};
}

const TaskResult& result_of(const CpuResult& cpu, std::size_t index) {
  for (const auto& r : cpu.tasks)
    if (r.index == index) return r;
  ADD_FAILURE() << "no result for task " << index;
  return cpu.tasks.front();
}

std::vector<std::size_t> order_of(const CpuResult& cpu) {
  std::vector<std::size_t> out;
  for (const auto& r : cpu.tasks) out.push_back(r.index);
  return out;
}

TEST(AnalyseCpu, RateMonotonicAboveTheBoundIsFeasible) {
  // Buttazzo's exercise 4.3, listed out of priority order in the "file".
  const std::vector<TaskModel> tasks{task("c", 3, 10, 0), task("a", 1, 4, 1), task("b", 2, 6, 2)};
  const auto cpu = analyse_cpu(tasks, SchedulerKind::kRm, kNoOverhead);
  EXPECT_TRUE(cpu.feasible);
  EXPECT_EQ(cpu.test, CpuTest::kResponseTime);
  EXPECT_EQ(cpu.periodic, 3);
  EXPECT_TRUE(cpu.implicit_deadlines);
  EXPECT_NEAR(cpu.utilisation, 0.8833, 1e-4);
  EXPECT_NEAR(cpu.ll_bound, 0.7798, 1e-4);
  EXPECT_EQ(order_of(cpu), (std::vector<std::size_t>{1, 2, 0}));
  EXPECT_EQ(result_of(cpu, 0).response_ns, 10);
  EXPECT_EQ(result_of(cpu, 0).verdict, Verdict::kMeets);
  EXPECT_EQ(result_of(cpu, 0).reason, "");
  EXPECT_FALSE(result_of(cpu, 0).response_is_bound);
}

TEST(AnalyseCpu, RateMonotonicMissNamesTheResponseTime) {
  const std::vector<TaskModel> tasks{task("fast", 2'000'000, 5'000'000, 0), task("slow", 4'000'000, 7'000'000, 1)};
  const auto cpu = analyse_cpu(tasks, SchedulerKind::kRm, kNoOverhead);
  EXPECT_FALSE(cpu.feasible);
  EXPECT_EQ(result_of(cpu, 0).verdict, Verdict::kMeets);
  EXPECT_EQ(result_of(cpu, 1).verdict, Verdict::kCanMiss);
  EXPECT_EQ(result_of(cpu, 1).response_ns, 8'000'000);
  EXPECT_EQ(result_of(cpu, 1).reason, "response time 8 ms > deadline 7 ms");
}

TEST(AnalyseCpu, DeadlineMonotonicOrdersByDeadline) {
  // Burns and Wellings' set: feasible by deadline, not by period.
  const std::vector<TaskModel> tasks{task("a", 3, 20, 0, 5), task("b", 3, 15, 1, 7), task("c", 4, 10, 2),
                                     task("d", 3, 20, 3)};
  const auto dm = analyse_cpu(tasks, SchedulerKind::kDm, kNoOverhead);
  EXPECT_TRUE(dm.feasible);
  EXPECT_FALSE(dm.implicit_deadlines);
  EXPECT_EQ(order_of(dm), (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(result_of(dm, 3).response_ns, 20);
  const auto rm = analyse_cpu(tasks, SchedulerKind::kRm, kNoOverhead);
  EXPECT_FALSE(rm.feasible);
  EXPECT_EQ(result_of(rm, 0).verdict, Verdict::kCanMiss);
}

TEST(AnalyseCpu, EqualPeriodsInterfereBothWays) {
  // Same-rate tasks run in data-flow order, not file order: each counts the other.
  const std::vector<TaskModel> tasks{task("pid", 200, 1000, 0), task("robot", 300, 1000, 1)};
  const auto cpu = analyse_cpu(tasks, SchedulerKind::kRm, kNoOverhead);
  EXPECT_EQ(result_of(cpu, 0).response_ns, 500);
  EXPECT_EQ(result_of(cpu, 1).response_ns, 500);
  EXPECT_EQ(order_of(cpu), (std::vector<std::size_t>{0, 1}));
}

TEST(AnalyseCpu, TheOverheadIsPartOfEveryC) {
  const std::vector<TaskModel> tasks{task("a", 1'000'000, 4'000'000, 0), task("b", 2'000'000, 6'000'000, 1)};
  const auto cpu = analyse_cpu(tasks, SchedulerKind::kRm, AnalysisOptions{.overhead_ns = 1'000});
  EXPECT_EQ(result_of(cpu, 0).demand->c_ns, 1'001'000);
  EXPECT_EQ(result_of(cpu, 1).response_ns, 3'002'000);
}

TEST(AnalyseCpu, EdfFeasibleGivesTheDeadlineAsBound) {
  const std::vector<TaskModel> tasks{task("a", 2, 5, 0), task("b", 4, 7, 1)};
  const auto cpu = analyse_cpu(tasks, SchedulerKind::kEdf, kNoOverhead);
  EXPECT_TRUE(cpu.feasible);
  EXPECT_EQ(cpu.test, CpuTest::kEdfUtilisation);
  EXPECT_TRUE(result_of(cpu, 1).response_is_bound);
  EXPECT_EQ(result_of(cpu, 1).response_ns, 7);
}

TEST(AnalyseCpu, EdfConstrainedDeadlinesBothWays) {
  std::vector<TaskModel> tasks{task("a", 2, 6, 0, 4), task("b", 2, 8, 1, 5), task("c", 3, 9, 2, 7)};
  auto cpu = analyse_cpu(tasks, SchedulerKind::kEdf, kNoOverhead);
  EXPECT_TRUE(cpu.feasible);
  EXPECT_EQ(cpu.test, CpuTest::kEdfProcessorDemand);
  tasks[2].deadline_ns = 6;
  cpu = analyse_cpu(tasks, SchedulerKind::kEdf, kNoOverhead);
  EXPECT_FALSE(cpu.feasible);
  EXPECT_EQ(cpu.edf.outcome, EdfOutcome::kDemandExceeded);
  for (const auto& r : cpu.tasks) {
    EXPECT_EQ(r.verdict, Verdict::kCanMiss);
    EXPECT_EQ(r.reason, "the jobs due in the first 6 ns need 7 ns");
  }
}

TEST(AnalyseCpu, EdfOverloaded) {
  const auto cpu =
      analyse_cpu(std::vector<TaskModel>{task("a", 3, 5, 0), task("b", 3, 6, 1)}, SchedulerKind::kEdf, kNoOverhead);
  EXPECT_FALSE(cpu.feasible);
  EXPECT_EQ(cpu.tasks[0].reason, "overloaded: U = 1.100 > 1");
}

TEST(AnalyseCpu, MufGuaranteesTheHardTasksWhereRmDoesNot) {
  // Hard a (2, 4), b (3, 10); soft c (2, 5), d (1, 20). U = 1.25.
  const std::vector<TaskModel> tasks{task("a", 2, 4, 0), task("b", 3, 10, 1), task("c", 2, 5, 2, 0, false),
                                     task("d", 1, 20, 3, 0, false)};
  const auto muf = analyse_cpu(tasks, SchedulerKind::kMuf, kNoOverhead);
  EXPECT_TRUE(muf.feasible);
  EXPECT_EQ(muf.test, CpuTest::kMufCriticalSet);
  EXPECT_EQ(order_of(muf), (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_TRUE(result_of(muf, 1).critical);
  EXPECT_EQ(result_of(muf, 1).verdict, Verdict::kMeets);
  EXPECT_EQ(result_of(muf, 2).verdict, Verdict::kNoGuarantee);
  EXPECT_FALSE(result_of(muf, 2).critical);
  EXPECT_EQ(result_of(muf, 3).verdict, Verdict::kNoGuarantee);  // (1, 20) would fit, but the set has ended
  EXPECT_EQ(result_of(muf, 3).reason,
            "outside the critical set, which admits the shortest periods first while they fit");
  EXPECT_NEAR(muf.edf.utilisation, 0.8, 1e-9);  // the critical set's

  const auto rm = analyse_cpu(tasks, SchedulerKind::kRm, kNoOverhead);
  EXPECT_FALSE(rm.feasible);
  // b is below a and the soft c: 0.5 + 0.4 + 0.3 = 1.2 of the processor at its level.
  EXPECT_EQ(result_of(rm, 1).verdict, Verdict::kCanMiss);
  EXPECT_EQ(result_of(rm, 1).reason,
            "overloaded: it and the tasks at or above its priority need 1.200 of the processor");
}

TEST(AnalyseCpu, MufHardTaskThatDoesNotFit) {
  const std::vector<TaskModel> tasks{task("x", 3, 6, 0), task("y", 3, 5, 1)};
  const auto cpu = analyse_cpu(tasks, SchedulerKind::kMuf, kNoOverhead);
  EXPECT_FALSE(cpu.feasible);
  EXPECT_EQ(result_of(cpu, 1).verdict, Verdict::kMeets);
  EXPECT_EQ(result_of(cpu, 0).verdict, Verdict::kCanMiss);
  EXPECT_FALSE(result_of(cpu, 0).critical);  // left out, so that y keeps its guarantee
  EXPECT_TRUE(cpu.hard_left_out);
  EXPECT_EQ(result_of(cpu, 0).reason, "hard, but does not fit in the critical set: with it, overloaded: U = 1.100 > 1");
}

TEST(AnalyseCpu, MufChecksTheRunsCriticalSetWithItsOwnC) {
  // From a file: a's C is known to the run (wcet: 2 ms), b's only to analysis (3 ms measured), c
  // is soft (1 ms of 10). The run admits a, then b unchecked, and so no soft task: c is outside.
  constexpr std::int64_t kMs = 1'000'000;
  std::vector<TaskModel> tasks{task("a", 2 * kMs, 5 * kMs, 0), task("b", 3 * kMs, 10 * kMs, 1),
                               task("c", 1 * kMs, 10 * kMs, 2, 0, false)};
  tasks[0].run_wcet_ns = 2 * kMs;
  tasks[1].run_wcet_ns = 0;
  tasks[2].run_wcet_ns = 1 * kMs;
  auto cpu = analyse_cpu(tasks, SchedulerKind::kMuf, kNoOverhead);
  EXPECT_TRUE(cpu.feasible);  // 0.4 + 0.3 with analysis' C
  EXPECT_TRUE(result_of(cpu, 1).critical);
  EXPECT_EQ(result_of(cpu, 1).verdict, Verdict::kMeets);
  EXPECT_FALSE(result_of(cpu, 2).critical);
  EXPECT_EQ(result_of(cpu, 2).reason,
            "outside the critical set: a hard task's execution time is not known before the run (give it a wcet), so "
            "no soft task is admitted");
  // b turns out to take 7 ms: the set the run uses fails, and every critical task can miss.
  tasks[1].wcet_ns = 7 * kMs;
  cpu = analyse_cpu(tasks, SchedulerKind::kMuf, kNoOverhead);
  EXPECT_FALSE(cpu.feasible);
  EXPECT_FALSE(cpu.hard_left_out);
  EXPECT_EQ(result_of(cpu, 0).verdict, Verdict::kCanMiss);
  EXPECT_EQ(result_of(cpu, 0).reason, "the critical set fails its EDF test: overloaded: U = 1.100 > 1");
  EXPECT_EQ(result_of(cpu, 1).verdict, Verdict::kCanMiss);
}

TEST(AnalyseCpu, UnknownExecutionTimes) {
  // rm: the task itself and every task below it cannot be bounded; those above it can.
  const std::vector<TaskModel> tasks{task("a", 1, 4, 0), task("b", 0, 6, 1), task("c", 1, 8, 2)};
  const auto rm = analyse_cpu(tasks, SchedulerKind::kRm, kNoOverhead);
  EXPECT_FALSE(rm.feasible);
  EXPECT_FALSE(rm.utilisation_complete);
  EXPECT_EQ(result_of(rm, 0).verdict, Verdict::kMeets);
  EXPECT_EQ(result_of(rm, 1).reason, "execution time unknown (give the task a wcet, or use --wcet-from)");
  EXPECT_EQ(result_of(rm, 2).reason, "cannot be bounded: b, at or above its priority, has an unknown execution time");
  // edf: nobody can be bounded.
  const auto edf = analyse_cpu(tasks, SchedulerKind::kEdf, kNoOverhead);
  EXPECT_EQ(result_of(edf, 0).verdict, Verdict::kCanMiss);
}

TEST(AnalyseCpu, ServersCountAsPeriodicTasksOfBudgetPlusOneJob) {
  // A server of budget 2 every 10, serving jobs of at most 1, beside a hard (5, 10): 3 + 5 = 8.
  std::vector<TaskModel> tasks{task("ctl", 5, 10, 0)};
  tasks.push_back(
      TaskModel{.name = "cmd", .wcet_ns = 2, .job_wcet_ns = 1, .period_ns = 10, .server = true, .file_index = 1});
  const auto cpu = analyse_cpu(tasks, SchedulerKind::kRm, kNoOverhead);
  EXPECT_TRUE(cpu.feasible);
  EXPECT_EQ(result_of(cpu, 1).demand->c_ns, 3);
  EXPECT_EQ(result_of(cpu, 1).response_ns, 8);
  EXPECT_EQ(cpu.periodic, 2);
}

TEST(AnalyseCpu, BackgroundTasksAreListedLastWithoutCounting) {
  const std::vector<TaskModel> tasks{task("bg", 5, 0, 0), task("a", 1, 4, 1)};
  for (const auto s : {SchedulerKind::kRm, SchedulerKind::kDm, SchedulerKind::kEdf, SchedulerKind::kMuf}) {
    const auto cpu = analyse_cpu(tasks, s, kNoOverhead);
    EXPECT_TRUE(cpu.feasible);
    EXPECT_EQ(cpu.periodic, 1);
    ASSERT_EQ(cpu.tasks.size(), 2U);
    EXPECT_EQ(cpu.tasks.back().index, 0U);
    EXPECT_EQ(cpu.tasks.back().verdict, Verdict::kBackground);
  }
}

TEST(AnalyseCpu, NoTasks) {
  const auto cpu = analyse_cpu(std::vector<TaskModel>{}, SchedulerKind::kRm);
  EXPECT_TRUE(cpu.feasible);
  EXPECT_EQ(cpu.test, CpuTest::kNone);
}

TEST(AnalyseConfiguration, EachCpuOnItsOwnWithGlobalIndices) {
  const std::vector<TaskModel> tasks{task("a", 2, 5, 0), task("b", 4, 7, 1), task("c", 1, 10, 2)};
  const std::vector<int> cpu_of{0, 1, 1};
  const std::vector<int> cpus{0, 1, 2};
  const auto r = analyse_configuration(tasks, cpu_of, cpus, SchedulerKind::kRm, kNoOverhead);
  EXPECT_TRUE(r.feasible);  // (2, 5) alone, and (4, 7) with (1, 10) on the other
  ASSERT_EQ(r.cpus.size(), 3U);
  EXPECT_EQ(r.cpus[0].cpu, 0);
  EXPECT_EQ(order_of(r.cpus[1]), (std::vector<std::size_t>{1, 2}));
  EXPECT_TRUE(r.cpus[2].tasks.empty());
  // All three on one CPU: b misses.
  const auto one =
      analyse_configuration(tasks, std::vector<int>{0, 0, 0}, std::vector<int>{0}, SchedulerKind::kRm, kNoOverhead);
  EXPECT_FALSE(one.feasible);
}

// A same-rate chain split over CPUs: the consumer's wait for its producer is its release jitter
// (docs/scheduling.md, "A chain across CPUs"). p (2, 10) on CPU 0 feeds c (1, 10) on CPU 1, beside
// x (1, 10), which reads nothing of p.
std::vector<TaskModel> split_pair() {
  std::vector<TaskModel> tasks{task("p", 2, 10, 0), task("c", 1, 10, 1), task("x", 1, 10, 2)};
  tasks[1].same_rate_producers = {0};
  return tasks;
}

TEST(AnalyseConfiguration, AConsumerOnAnotherCpuWaitsItsProducersResponseTime) {
  const auto tasks = split_pair();
  const std::vector<int> cpu_of{0, 1, 1};
  const std::vector<int> cpus{0, 1};
  // edf: no exact response time, but p's CPU is busy for at most 2 (its longest busy period) from
  // p's release, so c waits up to 2; every task has a thread of its own, so x does not wait.
  const auto edf = analyse_configuration(tasks, cpu_of, cpus, SchedulerKind::kEdf, kNoOverhead);
  EXPECT_TRUE(edf.feasible);
  EXPECT_EQ(edf.cpus[0].busy_period_ns, 2);
  EXPECT_EQ(result_of(edf.cpus[1], 1).release_jitter_ns, 2);
  EXPECT_EQ(result_of(edf.cpus[1], 1).verdict, Verdict::kMeets);
  EXPECT_EQ(result_of(edf.cpus[1], 2).release_jitter_ns, 0);
  // With c's deadline at 2 the wait leaves it no time: D - J = 0.
  auto tight = tasks;
  tight[1].deadline_ns = 2;
  const auto late = analyse_configuration(tight, cpu_of, cpus, SchedulerKind::kEdf, kNoOverhead);
  EXPECT_FALSE(late.feasible);
  EXPECT_EQ(result_of(late.cpus[1], 1).verdict, Verdict::kCanMiss);

  // rm: R(p) = 2 exactly, so c waits up to 2: R(c) = 2 + 1 + 1 (x, same priority) = 4. x shares
  // c's thread (one CPU, one period) and runs after it, so it waits as long: R(x) = 4 too.
  const auto rm = analyse_configuration(tasks, cpu_of, cpus, SchedulerKind::kRm, kNoOverhead);
  EXPECT_TRUE(rm.feasible);
  EXPECT_EQ(result_of(rm.cpus[0], 0).response_ns, 2);
  const auto& c = result_of(rm.cpus[1], 1);
  const auto& x = result_of(rm.cpus[1], 2);
  EXPECT_EQ(c.release_jitter_ns, 2);
  EXPECT_EQ(c.response_ns, 4);
  EXPECT_EQ(c.reason, "after waiting up to 2 ns for p on another CPU");
  EXPECT_EQ(x.release_jitter_ns, 2);
  EXPECT_EQ(x.response_ns, 4);
  EXPECT_EQ(x.reason, "after waiting up to 2 ns behind c, on its thread, which waits for p on another CPU");
}

TEST(AnalyseConfiguration, OnOneCpuNobodyWaits) {
  const auto tasks = split_pair();
  const std::vector<int> cpus{0};
  const auto rm = analyse_configuration(tasks, std::vector<int>{0, 0, 0}, cpus, SchedulerKind::kRm, kNoOverhead);
  for (const auto& r : rm.cpus[0].tasks) EXPECT_EQ(r.release_jitter_ns, 0);
  EXPECT_EQ(result_of(rm.cpus[0], 1).response_ns, 4) << "the three share the priority: 2 + 1 + 1";
}

TEST(AnalyseConfiguration, AProducerWithoutABoundLeavesItsConsumerWithoutOne) {
  auto tasks = split_pair();
  tasks[0].wcet_ns = 11;  // p cannot meet its deadline of 10
  const auto rm =
      analyse_configuration(tasks, std::vector<int>{0, 1, 1}, std::vector<int>{0, 1}, SchedulerKind::kRm, kNoOverhead);
  EXPECT_FALSE(rm.feasible);
  EXPECT_EQ(result_of(rm.cpus[1], 1).verdict, Verdict::kCanMiss);
  EXPECT_EQ(result_of(rm.cpus[1], 1).reason, "cannot be bounded: it waits for p on another CPU, which has no bound");
  EXPECT_EQ(result_of(rm.cpus[1], 2).reason,
            "cannot be bounded: c, on its thread, waits for p on another CPU, which has no bound");
}

}  // namespace
}  // namespace chimera::analysis
