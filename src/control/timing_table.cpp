#include "chimera/control/timing_table.hpp"

#include <fmt/format.h>

#include "chimera/control/text_table.hpp"

namespace chimera {

namespace {

constexpr std::int64_t kUs = 1'000;
constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kS = 1'000'000'000;

using Align = TextTable::Align;

// Columns both tables start with: who the task is and how far it got.
std::vector<TextTable::Column> identity_columns() {
  return {{"task", Align::kLeft},    {"module", Align::kLeft},  {"state", Align::kLeft},
          {"period", Align::kRight}, {"cycles", Align::kRight}, {"missed", Align::kRight}};
}

std::vector<std::string> identity_cells(const TaskSnapshot& t) {
  return {t.name,
          t.module,
          std::string(state_name(t.state)),
          format_period(t.period_ns),
          fmt::format("{}", t.stats.cycles),
          fmt::format("{}", t.stats.missed)};
}

}  // namespace

std::string format_duration(std::int64_t ns) {
  const auto v = static_cast<double>(ns);
  const std::int64_t magnitude = ns < 0 ? -ns : ns;
  if (magnitude < kUs) return fmt::format("{} ns", ns);
  if (magnitude < kMs) return fmt::format("{:.1f} µs", v / kUs);
  if (magnitude < kS) return fmt::format("{:.2f} ms", v / kMs);
  return fmt::format("{:.3f} s", v / kS);
}

std::string format_period(std::int64_t ns) {
  if (ns <= 0) return "aperiodic";
  // Exact values read as the file wrote them; others (e.g. from a frequency) fall back.
  if (ns % kS == 0) return fmt::format("{} s", ns / kS);
  if (ns >= kMs && ns % kMs == 0) return fmt::format("{} ms", ns / kMs);
  if (ns >= kUs && ns % kUs == 0) return fmt::format("{} µs", ns / kUs);
  if (ns < kUs) return fmt::format("{} ns", ns);
  if (ns < kMs) return fmt::format("{:.3f} µs", static_cast<double>(ns) / kUs);
  return fmt::format("{:.3f} ms", static_cast<double>(ns) / kMs);
}

std::string status_table(std::span<const TaskSnapshot> tasks) {
  bool any_error = false;
  for (const auto& t : tasks) any_error = any_error || !t.last_error.empty();

  auto columns = identity_columns();
  columns.insert(columns.begin() + 3, {"cpu", Align::kRight});  // the assignment, pinned or automatic
  if (any_error) columns.push_back({"last error", Align::kLeft});
  TextTable table(std::move(columns));
  for (const auto& t : tasks) {
    auto cells = identity_cells(t);
    cells.insert(cells.begin() + 3, fmt::format("{}", t.cpu));
    if (any_error) cells.push_back(t.last_error);
    table.add_row(std::move(cells));
  }
  return table.render();
}

std::string timing_table(std::span<const TaskSnapshot> tasks) {
  // Timing failures other than late cycles get columns only when some task has them.
  bool overruns = false;
  bool skipped = false;
  for (const auto& t : tasks) {
    overruns = overruns || t.stats.overruns != 0;
    skipped = skipped || t.stats.skipped != 0;
  }
  auto columns = identity_columns();
  if (overruns) columns.push_back({"overruns", Align::kRight});
  if (skipped) columns.push_back({"skipped", Align::kRight});
  for (const char* header : {"exec mean", "exec max", "latency p50", "latency p99", "latency max"})
    columns.push_back({header, Align::kRight});
  TextTable table(std::move(columns));
  for (const auto& t : tasks) {
    auto cells = identity_cells(t);
    const auto& s = t.stats;
    if (overruns) cells.push_back(fmt::format("{}", s.overruns));
    if (skipped) cells.push_back(fmt::format("{}", s.skipped));
    // A task that never cycled has no figures; a dash says so better than "0 ns".
    auto figure = [&](std::int64_t ns) { return s.cycles == 0 ? std::string("-") : format_duration(ns); };
    for (std::int64_t ns : {s.exec_mean_ns, s.exec_max_ns, s.latency_p50_ns, s.latency_p99_ns, s.latency_max_ns})
      cells.push_back(figure(ns));
    table.add_row(std::move(cells));
  }
  return table.render();
}

}  // namespace chimera
