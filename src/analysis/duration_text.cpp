#include "analysis/detail/duration_text.hpp"

#include <array>
#include <string_view>

#include <fmt/format.h>

namespace chimera::analysis::detail {

std::string duration_text(std::int64_t ns, DurationStyle style) {
  struct Unit {
    std::int64_t ns;
    std::string_view display;
    std::string_view file;
  };
  constexpr std::array<Unit, 3> kUnits{{{1'000'000'000, "s", "s"}, {1'000'000, "ms", "ms"}, {1'000, "µs", "us"}}};
  const std::string_view gap = style == DurationStyle::kDisplay ? " " : "";
  const std::int64_t magnitude = ns < 0 ? -ns : ns;
  for (const auto& unit : kUnits) {
    // Three decimals at most: the value must be a whole number of thousandths of the unit.
    if (magnitude < unit.ns || magnitude % (unit.ns / 1000) != 0) continue;
    const std::int64_t whole = ns / unit.ns;
    std::int64_t frac = magnitude % unit.ns / (unit.ns / 1000);
    const std::string_view name = style == DurationStyle::kDisplay ? unit.display : unit.file;
    if (frac == 0) return fmt::format("{}{}{}", whole, gap, name);
    int digits = 3;
    while (frac % 10 == 0) {
      frac /= 10;
      --digits;
    }
    return fmt::format("{}.{:0{}}{}{}", whole, frac, digits, gap, name);
  }
  return fmt::format("{}{}ns", ns, gap);
}

}  // namespace chimera::analysis::detail
