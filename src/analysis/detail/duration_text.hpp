#pragma once
// Durations as analysis writes them: exact, in the largest unit that keeps them exact with at most
// three decimals ("2.001 ms", "35.123 µs", "1234567 ns"). Private to src/analysis.

#include <cstdint>
#include <string>

namespace chimera::analysis::detail {

enum class DurationStyle {
  kDisplay,  // "2.001 ms", "35 µs": for people
  kFile,     // "2.001ms", "35us": what the subsystem file's parse_duration_ns() reads back exactly
};

std::string duration_text(std::int64_t ns, DurationStyle style = DurationStyle::kDisplay);

}  // namespace chimera::analysis::detail
