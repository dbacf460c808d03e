#pragma once
// The rule that keeps tasks of the same rate that feed each other from adding a cycle of lag
// (the failure of ros2_control issue 2420): at a release instant they shared, tasks of one
// period run in data-flow order, producers before consumers. A feedback loop is cut before the
// task listed first in the file, which therefore reads the loop's value from the previous cycle.
// docs/architecture.md explains it with Figure 4.

#include <vector>

#include "chimera/config/verify.hpp"

namespace chimera {

struct ReleaseOrder {
  /// Position of each task (index in the file) in the data-flow order of its period group.
  std::vector<int> rank;
  /// For each task, the same-period tasks that come before it and produce one of its in-vars:
  /// at a shared release, it starts only after they have finished.
  std::vector<std::vector<int>> predecessors;
};

ReleaseOrder compute_release_order(const ResolvedSubsystem& subsystem);

}  // namespace chimera
