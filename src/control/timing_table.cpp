#include "chimera/control/timing_table.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "chimera/core/duration_text.hpp"
#include "chimera/core/text_table.hpp"

namespace chimera {

namespace {

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

// A time on the subsystem's clock, as status shows it: seconds since start.
std::string clock_time(std::int64_t ns) { return fmt::format("{:.3f} s", static_cast<double>(ns) / 1e9); }

// The last error as status shows it: as it is while it is the task's state; once an operator's
// clear (or a kill) has ended it, or error() recovered from it, with when, so that an old error
// is never read as the task's present.
std::string last_error_cell(const TaskSnapshot& t) {
  if (t.last_error.empty()) return {};
  if (t.error_ended_by)
    return fmt::format("{} at {}, was: {}", *t.error_ended_by == Signal::kClear ? "cleared" : "killed",
                       clock_time(t.error_ended_ns), t.last_error);
  if (t.state == TaskState::kError) return t.last_error;
  return fmt::format("past, at {}: {}", clock_time(t.last_error_ns), t.last_error);
}

}  // namespace

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
    if (any_error) cells.push_back(last_error_cell(t));
    table.add_row(std::move(cells));
  }
  return table.render();
}

std::string timing_table(std::span<const TaskSnapshot> tasks, bool rt_check) {
  // Timing failures other than late cycles get columns only when some task has them.
  bool overruns = false;
  bool skipped = false;
  // With --rt-check a column of zeros is the answer the author wants, so it shows either way.
  bool rt_violations = rt_check;
  for (const auto& t : tasks) {
    overruns = overruns || t.stats.overruns != 0;
    skipped = skipped || t.stats.skipped != 0;
    rt_violations = rt_violations || t.stats.rt_violations != 0;
  }
  auto columns = identity_columns();
  if (overruns) columns.push_back({"overruns", Align::kRight});
  if (skipped) columns.push_back({"skipped", Align::kRight});
  if (rt_violations) columns.push_back({"rt violations", Align::kRight});
  // On the virtual clock execution times are simulated (virtual_exec plus what the module
  // charged), and the heading says so: they are not what the cycles cost the host.
  const bool simulated =
      std::any_of(tasks.begin(), tasks.end(), [](const TaskSnapshot& t) { return t.stats.exec_simulated; });
  columns.push_back({simulated ? "exec mean (simulated)" : "exec mean", Align::kRight});
  columns.push_back({simulated ? "exec max (simulated)" : "exec max", Align::kRight});
  for (const char* header : {"latency p50", "latency p99", "latency max"}) columns.push_back({header, Align::kRight});
  TextTable table(std::move(columns));
  for (const auto& t : tasks) {
    auto cells = identity_cells(t);
    const auto& s = t.stats;
    if (overruns) cells.push_back(fmt::format("{}", s.overruns));
    if (skipped) cells.push_back(fmt::format("{}", s.skipped));
    if (rt_violations) cells.push_back(fmt::format("{}", s.rt_violations));
    // A task that never cycled has no figures; a dash says so better than "0 ns".
    auto figure = [&](std::int64_t ns) { return s.cycles == 0 ? std::string("-") : format_duration(ns); };
    for (std::int64_t ns : {s.exec_mean_ns, s.exec_max_ns, s.latency_p50_ns, s.latency_p99_ns, s.latency_max_ns})
      cells.push_back(figure(ns));
    table.add_row(std::move(cells));
  }
  return table.render();
}

}  // namespace chimera
