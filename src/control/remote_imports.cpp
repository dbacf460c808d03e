#include "chimera/control/remote_imports.hpp"

#include <fmt/format.h>

#include "chimera/core/duration_text.hpp"
#include "chimera/core/text_table.hpp"

namespace chimera {

std::string remote_imports_table(const std::vector<RemoteImport>& imports) {
  if (imports.empty()) return {};
  using Align = TextTable::Align;
  bool any_refusal = false;
  for (const auto& i : imports) any_refusal = any_refusal || !i.refusal.empty();
  std::vector<TextTable::Column> columns{{"import", Align::kLeft},   {"state", Align::kLeft},    {"from", Align::kLeft},
                                         {"samples", Align::kRight}, {"refused", Align::kRight}, {"age", Align::kRight},
                                         {"max_age", Align::kRight}};
  if (any_refusal) columns.push_back({"refused from", Align::kLeft});
  TextTable table(std::move(columns));
  for (const auto& i : imports) {
    std::vector<std::string> cells{i.variable,
                                   i.stale ? "STALE" : "fresh",
                                   i.samples == 0 ? "-" : (i.writer.empty() ? "(no Chimera stamp)" : i.writer),
                                   fmt::format("{}", i.samples),
                                   fmt::format("{}", i.refused),
                                   i.age_ns < 0 ? "-" : format_duration(i.age_ns),
                                   format_duration(i.max_age_ns)};
    if (any_refusal) cells.push_back(i.refusal);
    table.add_row(std::move(cells));
  }
  return table.render();
}

}  // namespace chimera
