#pragma once
// Durations as analysis writes them: in the largest unit that keeps them exact with at most three
// decimals ("2.001 ms", "35.123 µs"). Private to src/analysis.

#include <cstdint>
#include <string>

namespace chimera::analysis::detail {

enum class DurationStyle {
  kDisplay,  // "2.001 ms", "35 µs", for people; "1500.001 ms" for 1500000942 ns: rounded up where
             // exact would take more than four digits before the point
  kFile,     // "2.001ms", "35us", "1500000.942us": exact, what parse_duration_ns() reads back
};

std::string duration_text(std::int64_t ns, DurationStyle style = DurationStyle::kDisplay);

}  // namespace chimera::analysis::detail
