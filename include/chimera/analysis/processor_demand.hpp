#pragma once
// Feasibility under EDF on one processor: the utilisation test where every deadline is at least
// the period (Liu and Layland 1973), the processor-demand criterion otherwise (Baruah, Rosier and
// Howell 1990), checked with Quick Processor-demand Analysis (QPA, Zhang and Burns 2009).

#include <cstdint>
#include <optional>
#include <span>

#include "chimera/analysis/task_model.hpp"

namespace chimera::analysis {

enum class EdfOutcome {
  kFeasible,        // every deadline is met
  kOverloaded,      // U > 1: no scheduler can meet every deadline
  kDemandExceeded,  // U <= 1, but some interval [0, t] holds more work with deadlines in it than t
  kGaveUp,          // the interval to check could not be bounded (U = 1 and a busy period too long)
};

struct EdfTest {
  EdfOutcome outcome = EdfOutcome::kGaveUp;
  double utilisation = 0;
  /// Every D >= T: the utilisation test alone decides (no interval is checked).
  bool utilisation_decides = false;
  /// The processor-demand test: the length L of the interval checked (the synchronous busy
  /// period, or the bound of George et al. 1996 when shorter) and the points QPA visited.
  std::int64_t bound_ns = 0;
  long points = 0;
  /// kDemandExceeded: an interval [0, t] and the demand h(t) > t of the jobs due in it.
  std::int64_t interval_ns = 0;
  std::int64_t demand_ns = 0;
};

/// h(t) = sum over tasks with D <= t of (floor((t - D) / T) + 1) C: the execution of every job
/// released at or after 0 and due by t, with all tasks released together at 0. Saturates at
/// INT64_MAX. A task with release jitter J counts with D - J instead of D (Spuri 1996): its job
/// may become ready J after its release and must still end by release + D.
[[nodiscard]] std::int64_t processor_demand(std::span<const Demand> tasks, std::int64_t t);

/// The longest busy period of the tasks on one CPU: the least L > 0 with L = sum ceil((L + J) / T) C.
/// Under a work-conserving scheduler (edf, and muf's critical tasks among themselves) the CPU is
/// busy from a job's release until it ends, so no job takes longer than L: a response-time bound
/// where EDF gives no exact one. nullopt when U > 1 or L cannot be found.
[[nodiscard]] std::optional<std::int64_t> longest_busy_period(std::span<const Demand> tasks);

/// The EDF test for tasks with known C (see demand_of()).
[[nodiscard]] EdfTest edf_test(std::span<const Demand> tasks);

}  // namespace chimera::analysis
