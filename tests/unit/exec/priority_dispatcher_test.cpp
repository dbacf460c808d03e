// The priorities the EDF / MUF dispatcher gives the jobs of one CPU: the policy's order
// (urgency.hpp), the most urgent at the top, background work at 1.

#include "exec/priority_dispatcher.hpp"

#include <gtest/gtest.h>

namespace chimera {
namespace {

struct Ranking {
  std::vector<TaskUrgency> urgency;
  std::vector<JobUrgency> jobs;
  std::vector<bool> active;
  void add(TaskUrgency u, JobUrgency j, bool is_active = true) {
    u.index = static_cast<int>(urgency.size());
    urgency.push_back(u);
    jobs.push_back(j);
    active.push_back(is_active);
  }
  std::vector<int> priorities(SchedulerKind policy) const {
    std::vector<int> order(urgency.size());
    std::vector<int> out(urgency.size());
    PriorityDispatcher::rank(policy, urgency, jobs, active, order, out);
    return out;
  }
};

constexpr int kTop = PriorityDispatcher::kTopJobPriority;

TEST(PriorityDispatcher, EdfRanksByAbsoluteDeadline) {
  Ranking r;
  r.add({.period_ns = 10}, {.release_ns = 0, .deadline_ns = 30});
  r.add({.period_ns = 20}, {.release_ns = 5, .deadline_ns = 12});
  r.add({.period_ns = 5}, {.release_ns = 0, .deadline_ns = 20});
  r.add({.period_ns = 5}, {.release_ns = 0, .deadline_ns = 1}, /*is_active=*/false);  // not released
  EXPECT_EQ(r.priorities(SchedulerKind::kEdf), (std::vector<int>{kTop - 2, kTop, kTop - 1, 0}));
}

TEST(PriorityDispatcher, MufPutsTheCriticalSetFirstThenDeadlineThenUserPriority) {
  Ranking r;
  r.add({.critical = false, .user_priority = 9}, {.release_ns = 0, .deadline_ns = 5});
  r.add({.critical = true, .user_priority = 0}, {.release_ns = 0, .deadline_ns = 50});
  r.add({.critical = true, .user_priority = 3}, {.release_ns = 0, .deadline_ns = 50});
  r.add({.critical = true, .user_priority = 0}, {.release_ns = 0, .deadline_ns = 40});
  EXPECT_EQ(r.priorities(SchedulerKind::kMuf), (std::vector<int>{kTop - 3, kTop - 2, kTop - 1, kTop}));
}

TEST(PriorityDispatcher, BackgroundWorkSitsAtOneAndManyJobsShareTheFloor) {
  Ranking r;
  r.add({.background = true}, {.release_ns = 0, .deadline_ns = 0});
  for (int i = 0; i < 100; ++i) r.add({}, {.release_ns = 0, .deadline_ns = 1000 + i});
  const auto p = r.priorities(SchedulerKind::kEdf);
  EXPECT_EQ(p[0], 1);
  EXPECT_EQ(p[1], kTop);
  EXPECT_EQ(p[2], kTop - 1);
  EXPECT_EQ(p[100], PriorityDispatcher::kLowestJobPriority);  // more jobs than levels: the last share it
}

}  // namespace
}  // namespace chimera
