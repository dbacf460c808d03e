#include "chimera/core/duration_text.hpp"

#include <array>
#include <string_view>

#include <fmt/format.h>

namespace chimera {
namespace {

constexpr std::int64_t kUs = 1'000;
constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kS = 1'000'000'000;

struct Unit {
  std::int64_t ns;
  std::string_view display;
  std::string_view file;
};
constexpr std::array<Unit, 3> kUnits{{{1'000'000'000, "s", "s"}, {1'000'000, "ms", "ms"}, {1'000, "µs", "us"}}};

// `thousandths` thousandths of `unit`, trailing zeros of the fraction dropped: "2.5 ms".
std::string in_unit(std::int64_t thousandths, const Unit& unit, DurationStyle style) {
  const std::string_view gap = style == DurationStyle::kDisplay ? " " : "";
  const std::string_view name = style == DurationStyle::kDisplay ? unit.display : unit.file;
  const std::int64_t whole = thousandths / 1000;
  std::int64_t frac = thousandths % 1000;
  if (frac == 0) return fmt::format("{}{}{}", whole, gap, name);
  int digits = 3;
  while (frac % 10 == 0) {
    frac /= 10;
    --digits;
  }
  return fmt::format("{}.{:0{}}{}{}", whole, frac, digits, gap, name);
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

std::string exact_duration_text(std::int64_t ns, DurationStyle style) {
  if (ns < 0)
    return fmt::format("-{}", exact_duration_text(-ns, style));  // (not "-" + ...: GCC 12's -Wrestrict misfires)
  std::size_t first = 0;
  while (first < kUnits.size() && ns < kUnits[first].ns) ++first;
  if (first == kUnits.size()) return fmt::format("{}{}ns", ns, style == DurationStyle::kDisplay ? " " : "");
  // Exact with at most three decimals, in the largest unit that manages it. For people, only
  // while the number stays short (under 10000); failing that, rounded up, never down, in the
  // smallest unit tried, so that a response time past its deadline never reads as within it.
  std::size_t last = first;
  for (std::size_t u = first; u < kUnits.size(); ++u) {
    const std::int64_t step = kUnits[u].ns / 1000;
    if (style == DurationStyle::kDisplay && u > first && ns / kUnits[u].ns >= 10'000) break;
    last = u;
    if (ns % step == 0) return in_unit(ns / step, kUnits[u], style);  // always, at last, in µs for files
  }
  const std::int64_t step = kUnits[last].ns / 1000;
  return in_unit((ns + step - 1) / step, kUnits[last], style);
}

}  // namespace chimera
