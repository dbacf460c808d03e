#pragma once
// Measuring execution times by running a configuration: `chimera analyze` does it on the virtual
// clock for tasks whose C nothing else gives; a profiling command can do it on the real clock.

#include <cstdint>
#include <string>

#include "chimera/analysis/wcet_profile.hpp"
#include "chimera/config/subsystem.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/core/result.hpp"

namespace chimera::cli {

/// How long `chimera analyze` runs a configuration to measure it: 20 periods of its slowest
/// task, at least 1 s, of simulated time (on the virtual clock a second of a 1 kHz task takes a
/// few milliseconds); shorter where that would be more than two million releases, but one period
/// of the slowest task at least.
std::int64_t measurement_length_ns(const SubsystemSpec& spec, const std::string& configuration);

/// How many runs `chimera analyze` makes of each configuration it measures.
inline constexpr int kMeasureRuns = 5;
/// The host time all the runs of one measure_profile() may take; past it the measurement is
/// refused (a task whose cycle takes far longer on the host than its period, or a file of very
/// many tasks), never a hang.
inline constexpr std::int64_t kMeasureHostLimitNs = 60'000'000'000;

/// Runs `configuration` of `spec` `runs` times for `for_ns` on `clock` (its own shared memory,
/// beside any running instance) and returns, per task that ran a cycle, the least over the runs
/// of its longest cycle, x a margin, as the budget (analysis::measured_entry()). The cycle's time
/// is, on the virtual clock, the simulated time (virtual_exec plus what the module charged, the
/// time the virtual clock's schedule is made of; x `simulated_margin`, entry.simulated) for a
/// task that has some, else (and on the real clock) the host's (x `margin`). On the virtual
/// clock every run takes the same inputs down the same paths, so a task's slowest cycle is there
/// in each run, while the machine's stalls (another process taking the CPU mid-cycle) are not
/// C and rarely strike every run. A task that fails while measured is reported as a warning;
/// its cycles still count. A signal (stop_requested()) or more than kMeasureHostLimitNs of host
/// time ends the runs with an error, the shared memory removed. Not real-time safe.
Result<analysis::WcetProfile> measure_profile(const SubsystemSpec& spec, const std::string& configuration,
                                              ClockKind clock, std::int64_t for_ns, int runs, double margin,
                                              double simulated_margin);

}  // namespace chimera::cli
