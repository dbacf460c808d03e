#include "switch_plan.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace chimera {

Result<SwitchPlan> plan_switch(const std::vector<SwitchTask>& tasks, const std::vector<std::string>& target) {
  SwitchPlan plan;
  std::vector<std::string> in_error;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const bool wanted = std::find(target.begin(), target.end(), tasks[i].name) != target.end();
    const TaskState s = tasks[i].state;
    if (wanted && s == TaskState::kError) in_error.push_back(tasks[i].name);
    if (!wanted && s == TaskState::kOn) plan.leaving.push_back(i);
    if (wanted && (s == TaskState::kOff || s == TaskState::kNotCreated)) plan.joining.push_back(i);
    if (wanted && s == TaskState::kNotCreated) plan.to_spawn.push_back(i);
  }
  if (!in_error.empty())
    return make_error(Errc::kState,
                      fmt::format("{} {} in ERROR (clear {} first)", fmt::join(in_error, ", "),
                                  in_error.size() == 1 ? "is" : "are", in_error.size() == 1 ? "it" : "them"));
  return plan;
}

}  // namespace chimera
