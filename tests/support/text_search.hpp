#pragma once

// Plain searches of a program's output, for the tests that used std::regex for patterns this
// simple: including <regex> cost each of those test files 17 s of compile time under ASAN (a
// one-function file, measured), which CI's clean machine pays in its 45 minutes.

#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace chimera::test {

/// What follows the first `before` in `text`, up to the first character of `stop` (or the end);
/// nullopt when `before` is not in `text`.
inline std::optional<std::string> text_after(const std::string& text, std::string_view before, std::string_view stop) {
  const auto at = text.find(before);
  if (at == std::string::npos) return std::nullopt;
  const auto from = at + before.size();
  const auto end = text.find_first_of(stop, from);
  return text.substr(from, end == std::string::npos ? std::string::npos : end - from);
}

/// The first line of `text` that begins with `start` (without its newline); nullopt if none does.
inline std::optional<std::string> line_starting(const std::string& text, std::string_view start) {
  std::size_t line = 0;
  while (line < text.size()) {
    const auto end = text.find('\n', line);
    const auto length = (end == std::string::npos ? text.size() : end) - line;
    if (std::string_view(text).substr(line, length).starts_with(start)) return text.substr(line, length);
    if (end == std::string::npos) break;
    line = end + 1;
  }
  return std::nullopt;
}

/// The whitespace-separated fields of `line`.
inline std::vector<std::string> fields_of(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> fields;
  for (std::string f; in >> f;) fields.push_back(f);
  return fields;
}

/// True when `s` is one or more of the characters of `allowed`.
inline bool only_of(std::string_view s, std::string_view allowed) {
  return !s.empty() && s.find_first_not_of(allowed) == std::string_view::npos;
}

/// `text` with every `from` replaced by `to`.
inline std::string replace_every(std::string text, std::string_view from, std::string_view to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

}  // namespace chimera::test
