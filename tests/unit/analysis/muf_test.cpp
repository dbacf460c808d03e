// MUF's critical set (Stewart and Khosla 1991): hard tasks first, then the others by period while
// the critical set stays feasible; a hard task that does not fit is not critical.

#include "chimera/analysis/muf.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace chimera::analysis {
namespace {

constexpr AnalysisOptions kNoOverhead{.overhead_ns = 0};

TaskModel task(const char* name, std::int64_t c, std::int64_t t, bool hard, int file_index, std::int64_t d = 0) {
  return TaskModel{
      .name = name, .wcet_ns = c, .period_ns = t, .deadline_ns = d, .hard = hard, .file_index = file_index};
}

TEST(MufCriticalSet, HardTasksAndTheSoftOnesThatFit) {
  // Hard (1, 4) and (3, 10), soft (2, 6): U = 0.25 + 0.3 + 0.333 = 0.883, all critical.
  const std::vector<TaskModel> tasks{task("a", 1, 4, true, 0), task("b", 2, 6, false, 1), task("c", 3, 10, true, 2)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_TRUE(set.feasible);
  EXPECT_EQ(set.critical, (std::vector<bool>{true, true, true}));
  EXPECT_TRUE(set.unfit_hard.empty());
}

TEST(MufCriticalSet, ASoftTaskThatDoesNotFitEndsTheSet) {
  // Hard (2, 4) and (3, 10) take 0.8. Soft by period: (2, 5) would make 1.2, so the set ends
  // there, and (1, 20) after it stays out too although 0.85 would fit: "shortest period first,
  // while the utilisation stays at or under 100%". Under rm the soft (2, 5) would outrank the
  // hard (3, 10) and make it miss.
  const std::vector<TaskModel> tasks{task("a", 2, 4, true, 0), task("b", 3, 10, true, 1), task("c", 2, 5, false, 2),
                                     task("d", 1, 20, false, 3)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_TRUE(set.feasible);
  EXPECT_EQ(set.critical, (std::vector<bool>{true, true, false, false}));
}

TEST(MufCriticalSet, AHardTaskThatDoesNotFitIsNotCritical) {
  // Hard (3, 5) then hard (3, 6): 1.1. The longer period is admitted second, does not fit and is
  // left out of the set, so that it cannot take the time of the one that fits (as the paper
  // has it: a task outside the critical set is not critical); the soft task gets nothing.
  const std::vector<TaskModel> tasks{task("x", 3, 6, true, 0), task("y", 3, 5, true, 1), task("s", 1, 100, false, 2)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_FALSE(set.feasible);
  EXPECT_EQ(set.unfit_hard, (std::vector<std::size_t>{0}));
  EXPECT_TRUE(set.unknown_hard.empty());
  EXPECT_EQ(set.critical, (std::vector<bool>{false, true, false}));
}

TEST(MufCriticalSet, LaterHardTasksAreJudgedAgainstTheSetThatHolds) {
  // y (3, 5) fits, x (3, 6) does not (1.1), z (2, 10) fits beside y alone (0.8): z is critical.
  const std::vector<TaskModel> tasks{task("x", 3, 6, true, 0), task("y", 3, 5, true, 1), task("z", 2, 10, true, 2)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_FALSE(set.feasible);
  EXPECT_EQ(set.unfit_hard, (std::vector<std::size_t>{0}));
  EXPECT_EQ(set.critical, (std::vector<bool>{false, true, true}));
}

TEST(MufCriticalSet, NoSoftTaskIsAdmittedOnceAHardTaskDoesNotFit) {
  // y (3, 5) is critical and x (3, 6) does not fit; soft s (1, 100) would fit beside y (0.61)
  // but is not admitted: the rule is that x then competes with s by deadline, outside the set,
  // instead of running below a soft task.
  const std::vector<TaskModel> tasks{task("x", 3, 6, true, 0), task("y", 3, 5, true, 1), task("s", 1, 100, false, 2)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_FALSE(set.critical[2]);
  // Without x, s is admitted: it is x, not the load, that keeps it out.
  const std::vector<TaskModel> without_x{task("y", 3, 5, true, 0), task("s", 1, 100, false, 1)};
  EXPECT_EQ(muf_critical_set(without_x, kNoOverhead).critical, (std::vector<bool>{true, true}));
}

TEST(MufCriticalSet, ConstrainedDeadlinesUseTheDemandTest) {
  // U = 0.4, but both are due 3 after release with 2 each.
  const std::vector<TaskModel> tasks{task("a", 2, 10, true, 0, 3), task("b", 2, 10, true, 1, 3)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_FALSE(set.feasible);
  EXPECT_EQ(set.unfit_hard, (std::vector<std::size_t>{1}));  // equal periods and deadlines: file order
}

TEST(MufCriticalSet, UnknownExecutionTimes) {
  // A soft task of unknown C ends the critical set. A hard one is critical but unchecked: nothing
  // is guaranteed by the set alone, and no soft task is admitted beside it.
  std::vector<TaskModel> tasks{task("a", 1, 4, true, 0), task("b", 0, 6, false, 1), task("c", 1, 8, false, 2)};
  auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_TRUE(set.feasible);
  EXPECT_EQ(set.critical, (std::vector<bool>{true, false, false}));
  tasks[0].wcet_ns = 0;
  tasks[1].wcet_ns = 1;
  set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_FALSE(set.feasible);
  EXPECT_TRUE(set.unfit_hard.empty());
  EXPECT_EQ(set.unknown_hard, (std::vector<std::size_t>{0}));
  EXPECT_EQ(set.critical, (std::vector<bool>{true, false, false}));
}

TEST(MufCriticalSet, TheRunsSetTakesTheCItKnowsBeforeItStarts) {
  // a's file gives no C (run_wcet_ns 0) but a measurement does (wcet_ns 3): the run cannot
  // check a, so a is critical unchecked and the soft b stays out; analysis checks that set.
  std::vector<TaskModel> tasks{task("a", 3, 5, true, 0), task("b", 1, 10, false, 1)};
  tasks[0].run_wcet_ns = 0;
  tasks[1].run_wcet_ns = 1;
  EXPECT_EQ(muf_critical_set(tasks, kNoOverhead).critical, (std::vector<bool>{true, true}));
  auto run = runtime_critical_set(tasks);
  EXPECT_EQ(run.critical, (std::vector<bool>{true, false}));
  EXPECT_EQ(run.unknown_hard, (std::vector<std::size_t>{0}));
  // With the C known to the run, and with its 1 µs overhead: (5, 10) twice is 100% without it.
  constexpr std::int64_t kMs = 1'000'000;
  tasks = {task("x", 5 * kMs, 10 * kMs, true, 0), task("y", 5 * kMs, 10 * kMs, true, 1)};
  tasks[0].run_wcet_ns = tasks[1].run_wcet_ns = 5 * kMs;
  EXPECT_TRUE(muf_critical_set(tasks, kNoOverhead).feasible);
  run = runtime_critical_set(tasks);
  EXPECT_EQ(run.critical, (std::vector<bool>{true, false}));
  EXPECT_EQ(run.unfit_hard, (std::vector<std::size_t>{1}));
}

TEST(MufCriticalSet, TheOverheadCounts) {
  // (5, 10) twice is exactly 100%; 1 of overhead per cycle makes the second not fit.
  const std::vector<TaskModel> tasks{task("a", 5, 10, true, 0), task("b", 5, 10, true, 1)};
  EXPECT_TRUE(muf_critical_set(tasks, kNoOverhead).feasible);
  EXPECT_FALSE(muf_critical_set(tasks, AnalysisOptions{.overhead_ns = 1}).feasible);
}

TEST(MufCriticalSet, BackgroundTasksAreNeverCritical) {
  const std::vector<TaskModel> tasks{task("a", 1, 4, true, 0), task("bg", 1, 0, true, 1)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_TRUE(set.feasible);
  EXPECT_EQ(set.critical, (std::vector<bool>{true, false}));
}

TEST(MufAdmissionOrder, PeriodThenDeadlineThenUserPriorityThenFile) {
  std::vector<TaskModel> tasks{task("a", 1, 10, false, 0), task("b", 1, 10, false, 1), task("c", 1, 10, false, 2, 5),
                               task("d", 1, 5, false, 3), task("bg", 1, 0, false, 4)};
  tasks[1].user_priority = 7;
  EXPECT_EQ(muf_admission_order(tasks), (std::vector<std::size_t>{3, 2, 1, 0}));
}

}  // namespace
}  // namespace chimera::analysis
