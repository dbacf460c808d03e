#pragma once
// Tables for the operator: the shell's `status`, and the timing table that `stats` shows and
// `chimera run` prints at the end. Durations are in human units ("12.3 µs", "1.25 ms").

#include <cstdint>
#include <span>
#include <string>

#include "chimera/exec/subsystem.hpp"

namespace chimera {

/// "850 ns", "12.3 µs", "1.25 ms", "2.000 s": the unit that keeps the number short.
std::string format_duration(std::int64_t ns);
/// A period as it would be written in the file: "1 ms", "250 µs", "33.333 ms"; "aperiodic" for 0.
std::string format_period(std::int64_t ns);

/// Columns task, module, state, period, cycles, missed (and the last error when a task has one).
/// Lines end in '\n'. Not real-time safe.
std::string status_table(std::span<const TaskSnapshot> tasks);
/// Columns task, module, state, period, cycles, missed, exec mean/max, latency p50/p99/max.
/// Lines end in '\n'. Not real-time safe.
std::string timing_table(std::span<const TaskSnapshot> tasks);

}  // namespace chimera
