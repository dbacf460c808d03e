#pragma once
// A plain-text table with aligned columns: the shell's `status`, the timing table, `chimera modules`.
// Widths count code points, not bytes, so "µs" lines up with "ms".

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace chimera {

class TextTable {
 public:
  enum class Align { kLeft, kRight };
  struct Column {
    std::string header;
    Align align = Align::kLeft;
  };

  explicit TextTable(std::vector<Column> columns) : columns_(std::move(columns)) {}

  /// One row; missing cells are left empty, extra cells are ignored.
  void add_row(std::vector<std::string> cells) { rows_.push_back(std::move(cells)); }

  /// Header line then one line per row, each ending in '\n'; two spaces between columns and no
  /// trailing blanks.
  [[nodiscard]] std::string render() const;

 private:
  std::vector<Column> columns_;
  std::vector<std::vector<std::string>> rows_;
};

/// Code points in a UTF-8 string: its width on a terminal for the text we print.
std::size_t display_width(std::string_view text);

}  // namespace chimera
