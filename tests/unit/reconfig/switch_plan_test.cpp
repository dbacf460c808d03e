// Who leaves, who joins, who must be created first.

#include "switch_plan.hpp"

#include <gtest/gtest.h>

namespace chimera {
namespace {

using S = TaskState;

TEST(SwitchPlan, LeavingJoiningAndToSpawn) {
  const std::vector<SwitchTask> tasks{
      {"vision", S::kOn}, {"ik", S::kOn}, {"dls", S::kNotCreated}, {"integ", S::kOff}, {"robot", S::kOn}};
  auto plan = plan_switch(tasks, {"vision", "dls", "integ", "robot"});
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->leaving, (std::vector<std::size_t>{1}));
  EXPECT_EQ(plan->joining, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(plan->to_spawn, (std::vector<std::size_t>{2}));
}

TEST(SwitchPlan, ATargetTaskInErrorIsRefused) {
  const std::vector<SwitchTask> tasks{{"a", S::kError}, {"b", S::kError}, {"c", S::kOn}};
  auto one = plan_switch(tasks, {"a", "c"});
  ASSERT_FALSE(one.ok());
  EXPECT_EQ(one.error().message, "a is in ERROR (clear it first)");
  auto two = plan_switch(tasks, {"a", "b"});
  ASSERT_FALSE(two.ok());
  EXPECT_EQ(two.error().message, "a, b are in ERROR (clear them first)");
  EXPECT_TRUE(plan_switch(tasks, {"c"}).ok()) << "a task in ERROR outside the target stays as it is";
}

}  // namespace
}  // namespace chimera
