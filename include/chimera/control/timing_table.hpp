#pragma once
// Tables for the operator: the shell's `status`, and the timing table that `stats` shows and
// `chimera run` prints at the end. Durations are in human units ("12.3 µs", "1.25 ms").

#include <cstdint>
#include <span>
#include <string>

#include "chimera/control/subsystem.hpp"

namespace chimera {

/// Columns task, module, state, period, cycles, missed (and the last error when a task has one:
/// as it is while the task is in that ERROR; "cleared at 1.400 s, was: ..." once an operator's
/// clear or a kill ended it; "past, at 1.250 s: ..." for one that never put the task in ERROR
/// or that an earlier state change left behind).
/// Lines end in '\n'. Not real-time safe.
std::string status_table(std::span<const TaskSnapshot> tasks);
/// Columns task, module, state, period, cycles, missed, exec mean/max, latency p50/p99/max; an
/// "rt violations" column when `rt_check` (the run counted them) or when any task has some.
/// Lines end in '\n'. Not real-time safe.
std::string timing_table(std::span<const TaskSnapshot> tasks, bool rt_check = false);

}  // namespace chimera
