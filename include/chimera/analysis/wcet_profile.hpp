#pragma once
// The profile file: measured execution budgets per task, written by `chimera profile` (or made
// by hand) and read by `chimera analyze --wcet-from`. docs/scheduling.md describes the format:
//
//   # written by chimera profile
//   subsystem: fig4
//   clock: real
//   tasks:
//     traj: { wcet: 35us, exec_max: 35us, exec_p99: 20us, cycles: 10000 }
//
// `wcet` (required, > 0) is the budget analysis uses; the others record what it came from.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/core/result.hpp"

namespace chimera::analysis {

/// One task's figures.
struct ProfileEntry {
  std::string task;
  std::int64_t wcet_ns = 0;                 // the budget: what analysis takes as C
  std::optional<std::int64_t> exec_max_ns;  // the longest cycle seen
  std::optional<std::int64_t> exec_p99_ns;  // 99% of the cycles took at most this
  std::optional<std::uint64_t> cycles;      // how many cycles were seen
  int line = 0;                             // where the entry stands in the file read; 0: not read
  bool simulated = false;                   // measured in simulated time (virtual clock), not host time
};

struct WcetProfile {
  std::string file;                 // where it was read from ("" when made in memory): names it in messages
  std::string subsystem;            // the subsystem measured
  std::string clock;                // "real", "virtual", or "" when not said
  std::vector<ProfileEntry> tasks;  // in file order
  int subsystem_line = 0;

  [[nodiscard]] const ProfileEntry* find(std::string_view task) const {
    for (const auto& e : tasks)
      if (e.task == task) return &e;
    return nullptr;
  }
};

/// The margin `chimera analyze` puts on the longest cycle of its own short virtual-clock run:
/// such a run sees warm caches and one run's inputs (docs/scheduling.md).
inline constexpr double kMeasuredMargin = 1.5;

/// A profile entry from a measurement: wcet = the longest cycle x `margin`, rounded up to the ns.
[[nodiscard]] ProfileEntry measured_entry(std::string task, std::int64_t exec_max_ns, std::uint64_t cycles,
                                          double margin, std::optional<std::int64_t> exec_p99_ns = std::nullopt);

/// Reads a profile file. Every problem is an Errc::kInvalidInput error of the form
/// "wcet.yaml:5: tasks.traj.wcet: problem": unknown keys, bad durations, a task written twice.
/// Not real-time safe.
Result<WcetProfile> read_wcet_profile_file(const std::string& path);
/// The same for text in memory; `file_name` is used in messages.
Result<WcetProfile> read_wcet_profile_text(std::string_view text, const std::string& file_name);

/// The file's text: a comment line, then subsystem, clock and one flow mapping per task, with
/// durations exact to the ns so that reading it back gives the same numbers.
[[nodiscard]] std::string format_wcet_profile(const WcetProfile& profile);
/// Writes format_wcet_profile() to `path`, replacing it. Not real-time safe.
Result<void> write_wcet_profile_file(const std::string& path, const WcetProfile& profile);

/// Whether `profile` was made for `spec`: the same subsystem name, and no task that the file
/// lacks. A mismatch is an Errc::kInvalidInput error naming the profile's file and line.
Result<void> check_profile_matches(const WcetProfile& profile, const SubsystemSpec& spec);

}  // namespace chimera::analysis
