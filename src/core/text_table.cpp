#include "chimera/core/text_table.hpp"

#include <algorithm>

namespace chimera {

std::size_t display_width(std::string_view text) {
  // UTF-8 continuation bytes are 10xxxxxx; every other byte starts a code point.
  return static_cast<std::size_t>(
      std::count_if(text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0U) != 0x80U; }));
}

std::string TextTable::render() const {
  std::vector<std::size_t> widths(columns_.size());
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    widths[c] = display_width(columns_[c].header);
    for (const auto& row : rows_)
      if (c < row.size()) widths[c] = std::max(widths[c], display_width(row[c]));
  }

  std::string out;
  auto emit_line = [&](auto cell_of) {
    std::string line;
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      const std::string_view cell = cell_of(c);
      const std::size_t pad = widths[c] - display_width(cell);
      if (c > 0) line += "  ";
      if (columns_[c].align == Align::kRight) line.append(pad, ' ');
      line += cell;
      if (columns_[c].align == Align::kLeft) line.append(pad, ' ');
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line;
    out += '\n';
  };

  emit_line([&](std::size_t c) -> std::string_view { return columns_[c].header; });
  for (const auto& row : rows_)
    emit_line([&](std::size_t c) -> std::string_view { return c < row.size() ? std::string_view(row[c]) : ""; });
  return out;
}

}  // namespace chimera
