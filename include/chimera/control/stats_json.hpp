#pragma once
// The machine-readable counterpart of the timing table: what `chimera run --stats-json FILE`
// writes at exit (contract section 2).

#include <cstdint>
#include <span>
#include <string>

#include "chimera/control/subsystem.hpp"
#include "chimera/core/result.hpp"

namespace chimera {

/// {"clock": "real"|"virtual", "switches": N, "tasks": {"<task>": {"module", "state",
/// "period_ns", "cycles", "missed", "exec_ns": {"mean", "max"}, "latency_ns": {"p50", "p99",
/// "max"}, "rt_violations"}}, "rt_check": whether rt_violations were counted}, tasks in the
/// order given. Indented for a person reading the file; compact on one line for a program (a
/// stream's timing frame: Figure 4's, after a second on the real clock, 8.6 kB instead of
/// 42 kB, the histograms' pairs no longer a line each). Not real-time safe.
enum class JsonLayout { kIndented, kCompact };
std::string stats_json(std::span<const TaskSnapshot> tasks, ClockKind clock, std::uint64_t switches,
                       bool rt_check = false, JsonLayout layout = JsonLayout::kIndented);

/// Writes stats_json() to `path`; an unwritable path is an Errc::kSystem error naming it.
Result<void> write_stats_json(const std::string& path, std::span<const TaskSnapshot> tasks, ClockKind clock,
                              std::uint64_t switches, bool rt_check = false);

}  // namespace chimera
