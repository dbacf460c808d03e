#pragma once
// Durations as text, for people and for files. Parsing them back is the loader's
// (chimera/config/loader.hpp, parse_duration_ns).

#include <cstdint>
#include <string>

namespace chimera {

/// "850 ns", "12.3 µs", "1.25 ms", "2.000 s": the unit that keeps the number short (tables).
std::string format_duration(std::int64_t ns);
/// A period as it would be written in the file: "1 ms", "250 µs", "33.333 ms"; "aperiodic" for 0.
std::string format_period(std::int64_t ns);

enum class DurationStyle {
  kDisplay,  // "2.001 ms", "35 µs", for people; "1500.001 ms" for 1500000942 ns: rounded up where
             // exact would take more than four digits before the point
  kFile,     // "2.001ms", "35us", "1500000.942us": exact, what parse_duration_ns() reads back
};

/// Exact with at most three decimals, in the largest unit that keeps it exact (analysis reports,
/// profile files). For people, rounded up (never down) where exact would be long, so that a
/// response time past its deadline never reads as within it.
std::string exact_duration_text(std::int64_t ns, DurationStyle style = DurationStyle::kDisplay);

}  // namespace chimera
