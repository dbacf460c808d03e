#include "executive.hpp"

#include "process_executive.hpp"
#include "real_executive.hpp"
#include "virtual_executive.hpp"

namespace chimera {

std::int64_t shortest_period(const std::vector<Task*>& tasks, const SwitchCommit& commit) {
  std::int64_t shortest = 0;
  for (const auto* list : {&commit.leaving, &commit.joining})
    for (const std::size_t i : *list)
      if (tasks[i]->periodic() && (shortest == 0 || tasks[i]->period_ns() < shortest)) shortest = tasks[i]->period_ns();
  return shortest;
}

std::unique_ptr<Executive> make_executive(ExecutiveSetup setup) {
  // The one place a clock is chosen.
  if (setup.clock == ClockKind::kVirtual) return std::make_unique<VirtualExecutive>(std::move(setup));
  if (setup.processes.block != nullptr) return std::make_unique<ProcessExecutive>(std::move(setup));
  return std::make_unique<RealExecutive>(std::move(setup));
}

}  // namespace chimera
