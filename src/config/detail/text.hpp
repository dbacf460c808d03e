#pragma once
// How names, shapes and values read in verification messages. Private to src/config.

#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "chimera/svt/elem_type.hpp"

namespace chimera::config_detail {

/// "a", "a and b", "a, b and c".
inline std::string join_names(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += (i + 1 == names.size()) ? " and " : ", ";
    out += names[i];
  }
  return out;
}

/// "f64[6]".
inline std::string shape_text(const VarShape& shape) {
  return fmt::format("{}[{}]", elem_name(shape.type), shape.count);
}

/// "6" for one number, "[1, 2]" for several.
inline std::string values_text(const std::vector<double>& values) {
  if (values.size() == 1) return fmt::format("{}", values.front());
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += fmt::format("{}{}", i != 0 ? ", " : "", values[i]);
  return out + "]";
}

}  // namespace chimera::config_detail
