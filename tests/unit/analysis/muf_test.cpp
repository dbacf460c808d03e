// MUF's critical set (Stewart and Khosla 1991): hard tasks first, then the others by period while
// the critical set stays feasible.

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

TEST(MufCriticalSet, AHardTaskThatDoesNotFitIsReported) {
  // Hard (3, 5) then hard (3, 6): 1.1. The longer period is admitted second and does not fit;
  // the soft task gets nothing.
  const std::vector<TaskModel> tasks{task("x", 3, 6, true, 0), task("y", 3, 5, true, 1), task("s", 1, 100, false, 2)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_FALSE(set.feasible);
  EXPECT_EQ(set.unfit_hard, (std::vector<std::size_t>{0}));
  EXPECT_EQ(set.critical, (std::vector<bool>{true, true, false}));  // every hard task is critical
}

TEST(MufCriticalSet, ConstrainedDeadlinesUseTheDemandTest) {
  // U = 0.4, but both are due 3 after release with 2 each.
  const std::vector<TaskModel> tasks{task("a", 2, 10, true, 0, 3), task("b", 2, 10, true, 1, 3)};
  const auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_FALSE(set.feasible);
  EXPECT_EQ(set.unfit_hard, (std::vector<std::size_t>{1}));  // equal periods and deadlines: file order
}

TEST(MufCriticalSet, UnknownExecutionTimes) {
  // A hard task of unknown C cannot be guaranteed; a soft one ends the critical set.
  std::vector<TaskModel> tasks{task("a", 1, 4, true, 0), task("b", 0, 6, false, 1), task("c", 1, 8, false, 2)};
  auto set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_TRUE(set.feasible);
  EXPECT_EQ(set.critical, (std::vector<bool>{true, false, false}));
  tasks[0].wcet_ns = 0;
  set = muf_critical_set(tasks, kNoOverhead);
  EXPECT_FALSE(set.feasible);
  EXPECT_EQ(set.unfit_hard, (std::vector<std::size_t>{0}));
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
