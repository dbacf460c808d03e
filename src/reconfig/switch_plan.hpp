#pragma once
// The first, checking half of a switch (STYLE: prepare off the real-time path, commit at a cycle
// boundary): which tasks leave, which join, which must be created first, and whether the target
// may run at all. Pure: it reads states and names, changes nothing.

#include <cstddef>
#include <string>
#include <vector>

#include "chimera/core/result.hpp"
#include "chimera/lifecycle/state.hpp"

namespace chimera {

struct SwitchTask {
  std::string name;
  TaskState state = TaskState::kNotCreated;
};

struct SwitchPlan {
  std::vector<std::size_t> leaving;   // ON, not in the target: off at the commit
  std::vector<std::size_t> joining;   // in the target, not ON: on at the commit
  std::vector<std::size_t> to_spawn;  // joining tasks that do not exist yet: init before the commit
};

/// The plan from the tasks as they are to the configuration `target` (task names). Refuses a
/// target task that is in ERROR (the operator clears it first). Not real-time safe.
Result<SwitchPlan> plan_switch(const std::vector<SwitchTask>& tasks, const std::vector<std::string>& target);

}  // namespace chimera
