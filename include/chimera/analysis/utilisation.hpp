#pragma once
// Processor utilisation U = sum C/T of a CPU's tasks, and the Liu and Layland bound.

#include <span>

#include "chimera/analysis/task_model.hpp"

namespace chimera::analysis {

/// sum C/T, for display and for comparisons that need not be exact.
[[nodiscard]] double utilisation(std::span<const Demand> tasks);

/// Whether sum C/T <= 1, decided exactly in integers (a set at exactly 1 is schedulable by EDF;
/// floating point cannot tell 1 from 1 + 1/LCM). Falls back to long double, with no tolerance,
/// only when the periods' least common multiple does not fit in 127 bits.
[[nodiscard]] bool utilisation_at_most_one(std::span<const Demand> tasks);

/// Liu and Layland (1973): n tasks with D = T are schedulable by rate-monotonic priorities when
/// U <= n (2^(1/n) - 1). 1 for n = 0; tends to ln 2 = 0.693.
[[nodiscard]] double liu_layland_bound(int n);

}  // namespace chimera::analysis
