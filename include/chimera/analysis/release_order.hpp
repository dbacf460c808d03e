#pragma once
// The rule that keeps tasks of the same rate that feed each other from adding a cycle of lag
// (the failure of ros2_control issue 2420): at a release instant they shared, tasks of one
// period run in data-flow order, producers before consumers. A feedback loop is cut before the
// task listed first in the file, which therefore reads the loop's value from the previous cycle.
// docs/architecture.md explains it with Figure 4.
//
// It lives in analysis because both sides need it: the executives order and wait by it, CPU
// assignment keeps a chain on one CPU by it, and analysis counts the waits of a chain that spans
// CPUs.

#include <vector>

#include "chimera/config/verify.hpp"

namespace chimera::analysis {

struct ReleaseOrder {
  /// Position of each task (index in the file) in the data-flow order of its period group.
  std::vector<int> rank;
  /// For each task, the same-period tasks that come before it and produce one of its in-vars:
  /// at a shared release, it starts only after they have finished.
  std::vector<std::vector<int>> predecessors;
  /// For each task, its *chain*: the tasks of its period that feed it or that it feeds, directly
  /// or through others of that period (a loop's back edge included). Named by the file index of
  /// the chain's first task; a task that feeds no task of its period and is fed by none, or has
  /// no period, is a chain of its own.
  std::vector<int> chain;
};

[[nodiscard]] ReleaseOrder compute_release_order(const ResolvedSubsystem& subsystem);

}  // namespace chimera::analysis
