#include "chimera/module/declarations.hpp"

#include <fmt/format.h>

namespace chimera {

std::string to_string(const Dim& d) {
  if (d.follows) return "any";
  if (d.symbol.empty()) return fmt::format("{}", d.factor);
  if (d.factor == 1) return d.symbol;
  return fmt::format("{}*{}", d.factor, d.symbol);
}

}  // namespace chimera
