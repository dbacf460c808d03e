#include "chimera/control/task_profile.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "chimera/control/timing_table.hpp"
#include "chimera/core/duration_text.hpp"

namespace chimera {

namespace {

constexpr int kBarWidth = 40;
constexpr std::size_t kMaxRows = 16;

using Buckets = std::vector<std::pair<std::int64_t, std::uint64_t>>;

// The histogram's buckets (about 3% wide) merged into at most kMaxRows rows of equal width on a
// log scale between the smallest and largest bucket, each a bar scaled to the fullest row.
std::string histogram(std::string_view title, const Buckets& buckets) {
  std::string out = fmt::format("{}:\n", title);
  if (buckets.empty()) return out + "  (no cycles yet)\n";
  const double lo = std::log(static_cast<double>(std::max<std::int64_t>(1, buckets.front().first)));
  const double hi = std::log(static_cast<double>(std::max<std::int64_t>(1, buckets.back().first)));
  const std::size_t rows = hi - lo < 1e-9 ? 1 : std::min(kMaxRows, buckets.size());
  std::vector<std::uint64_t> counts(rows, 0);
  std::vector<std::int64_t> upper(rows, 0);
  for (const auto& [bound, count] : buckets) {
    const double x = std::log(static_cast<double>(std::max<std::int64_t>(1, bound)));
    const double position = rows == 1 ? 0.0 : (x - lo) / (hi - lo) * static_cast<double>(rows - 1);
    const auto row = std::min(rows - 1, static_cast<std::size_t>(std::lround(position)));
    counts[row] += count;
    upper[row] = std::max(upper[row], bound);
  }
  const std::uint64_t most = *std::max_element(counts.begin(), counts.end());
  for (std::size_t r = 0; r < rows; ++r) {
    if (counts[r] == 0) continue;
    const auto bar =
        static_cast<int>(std::ceil(static_cast<double>(counts[r]) * kBarWidth / static_cast<double>(most)));
    out += fmt::format("  <= {:>10} {:>9}  {}\n", format_duration(upper[r]), counts[r],
                       std::string(static_cast<std::size_t>(bar), '#'));
  }
  return out;
}

}  // namespace

std::string task_profile(const TaskSnapshot& t) {
  const auto& s = t.stats;
  std::string out = fmt::format("{} ({}), {}, cpu {}, period {}\n", t.name, t.module, state_name(t.state), t.cpu,
                                format_period(t.period_ns));
  out += fmt::format("  cycles {}, missed {}, overruns {}, skipped {}, order timeouts {}\n", s.cycles, s.missed,
                     s.overruns, s.skipped, s.order_timeouts);
  if (s.cycles != 0) {
    out += fmt::format("  exec     mean {}, p50 {}, p99 {}, max {}{}\n", format_duration(s.exec_mean_ns),
                       format_duration(s.exec_p50_ns), format_duration(s.exec_p99_ns), format_duration(s.exec_max_ns),
                       s.exec_simulated ? " (simulated time)" : "");
    if (s.exec_simulated)
      out += fmt::format("  host     mean {}, max {} (what the cycles took on the host)\n",
                         format_duration(s.host_exec_mean_ns), format_duration(s.host_exec_max_ns));
    out += fmt::format("  latency  p50 {}, p99 {}, max {}\n", format_duration(s.latency_p50_ns),
                       format_duration(s.latency_p99_ns), format_duration(s.latency_max_ns));
    out += fmt::format("  response p99 {}, max {}\n", format_duration(s.response_p99_ns),
                       format_duration(s.response_max_ns));
  }
  out += histogram("execution time", s.exec_histogram);
  out += histogram("release latency", s.latency_histogram);
  return out;
}

}  // namespace chimera
