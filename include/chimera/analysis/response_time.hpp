#pragma once
// Exact response-time analysis for fixed priorities (rate- and deadline-monotonic): Joseph and
// Pandya (1986), Audsley et al. (1993), with Lehoczky's (1990) level-i busy period so that a
// deadline longer than the period is analysed right too.

#include <cstdint>
#include <span>
#include <vector>

#include "chimera/analysis/task_model.hpp"
#include "chimera/config/subsystem.hpp"

namespace chimera::analysis {

enum class RtaOutcome {
  kMeets,       // every job of the task finishes by its deadline
  kMisses,      // some job can finish after its deadline
  kOverloaded,  // the task and those at or above its priority need more than the processor
  kGaveUp,      // the level-i busy period is too long to walk (rare: U at that level ~ 1)
};

struct ResponseTime {
  RtaOutcome outcome = RtaOutcome::kGaveUp;
  /// The worst-case response time (kMeets, and kMisses when `exact`); for kMisses that is not
  /// exact, the latest completion found before giving up, already past the deadline.
  std::int64_t response_ns = 0;
  bool exact = false;
  /// Jobs of the task in its level-i busy period that were examined (1 when R <= T).
  int jobs = 0;
  /// Utilisation of the task and every task that interferes with it.
  double level_utilisation = 0;
};

/// The worst-case response time of `task`, from its release, when every task in `interference`
/// (those of higher or equal priority, the task itself excluded) can preempt it. Release jitter
/// (Demand::j_ns) counts both ways: the task's own delays its start, the others' can bring one
/// more job into a window. Integer arithmetic; exact without jitter, a safe upper bound with it.
[[nodiscard]] ResponseTime response_time(const Demand& task, std::span<const Demand> interference);

/// Bini and Baruah (2007): a bound on the response time of the first job after the critical
/// instant, (C + sum_j C_j (1 - U_j)) / (1 - sum_j U_j) over the interfering tasks j, from two sums
/// a caller can keep as prefix sums. Infinity when sum_j U_j >= 1. Where it is at most min(D, T),
/// every job meets its deadline (the busy period ends before the next release); it is a cheap
/// sufficient test, the exact answer is response_time().
[[nodiscard]] double response_time_upper_bound(std::int64_t c_ns, double interference_utilisation,
                                               double interference_weighted_c);

/// The rank of each task's priority under rm (by period) or dm (by relative deadline): 0 is the
/// highest. Tasks with equal periods (rm) or deadlines (dm) share a rank: they run in data-flow
/// order at a shared release (the same-rate rule, docs/architecture.md) whatever their place in
/// the file, so each can wait for the others and analysis counts them as mutual interference.
/// Background tasks get rank -1. `scheduler` must be kRm or kDm.
[[nodiscard]] std::vector<int> fixed_priority_ranks(std::span<const TaskModel> tasks, SchedulerKind scheduler);

/// Task indices from the highest priority to the lowest, equal ranks in file order (file_index),
/// background tasks left out.
[[nodiscard]] std::vector<std::size_t> fixed_priority_order(std::span<const TaskModel> tasks, SchedulerKind scheduler);

}  // namespace chimera::analysis
