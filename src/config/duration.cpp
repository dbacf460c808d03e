// Durations and frequencies of the subsystem file. Durations are parsed with integer arithmetic
// so that "2.5ms" is exactly 2'500'000 ns, never 2'499'999 after a round trip through double.

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"

namespace chimera {
namespace {

// "2.5ms" split into its digits and its unit; the number must be digits[.digits].
struct Decimal {
  std::string_view whole;
  std::string_view fraction;  // without trailing zeros, which add no precision
  std::string_view unit;
};

bool is_digit(char c) { return c >= '0' && c <= '9'; }

std::optional<Decimal> split_decimal(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size() && is_digit(text[i])) ++i;
  if (i == 0) return std::nullopt;
  Decimal d{text.substr(0, i), {}, {}};
  if (i < text.size() && text[i] == '.') {
    const std::size_t start = ++i;
    while (i < text.size() && is_digit(text[i])) ++i;
    if (i == start) return std::nullopt;  // "5.ms" is more likely a typo than a number
    d.fraction = text.substr(start, i - start);
    while (!d.fraction.empty() && d.fraction.back() == '0') d.fraction.remove_suffix(1);
  }
  d.unit = text.substr(i);
  return d;
}

// Exponent of ten of one unit in nanoseconds, or nullopt for an unknown unit.
std::optional<std::size_t> duration_exponent(std::string_view unit) {
  if (unit == "ns") return 0;
  if (unit == "us") return 3;
  if (unit == "ms") return 6;
  if (unit == "s") return 9;
  return std::nullopt;
}

constexpr std::array<std::int64_t, 10> kPow10 = {1,       10,        100,        1'000,       10'000,
                                                 100'000, 1'000'000, 10'000'000, 100'000'000, 1'000'000'000};

Error not_a_duration(std::string_view text) {
  return make_error(Errc::kInvalidInput,
                    fmt::format("\"{}\" is not a duration (use ns, us, ms or s, e.g. 10ms)", text));
}

Error not_a_frequency(std::string_view text) {
  return make_error(Errc::kInvalidInput, fmt::format("\"{}\" is not a frequency (use Hz or kHz, e.g. 100Hz)", text));
}

}  // namespace

Result<std::int64_t> parse_duration_ns(std::string_view text) {
  const bool negative = !text.empty() && text.front() == '-';
  const auto d = split_decimal(negative ? text.substr(1) : text);
  if (!d) return not_a_duration(text);
  const auto exponent = duration_exponent(d->unit);
  if (!exponent) return not_a_duration(text);
  if (negative) return make_error(Errc::kInvalidInput, fmt::format("\"{}\" is negative; a duration is >= 0", text));
  if (d->fraction.size() > *exponent)
    return make_error(Errc::kInvalidInput, fmt::format("\"{}\" is finer than the 1ns resolution", text));

  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  const auto too_large = [&] {
    return make_error(Errc::kInvalidInput, fmt::format("\"{}\" is too large (the limit is about 292 years)", text));
  };
  const std::int64_t scale = kPow10.at(*exponent);
  std::int64_t whole = 0;
  for (char c : d->whole) {
    if (whole > (kMax - (c - '0')) / 10) return too_large();
    whole = whole * 10 + (c - '0');
  }
  if (whole > kMax / scale) return too_large();
  std::int64_t fraction = 0;  // at most 9 digits: cannot overflow
  for (char c : d->fraction) fraction = fraction * 10 + (c - '0');
  fraction *= kPow10.at(*exponent - d->fraction.size());
  if (whole * scale > kMax - fraction) return too_large();
  return whole * scale + fraction;
}

Result<std::int64_t> parse_frequency_period_ns(std::string_view text) {
  if (!text.empty() && text.front() == '-') {
    if (split_decimal(text.substr(1))) return make_error(Errc::kInvalidInput, fmt::format("\"{}\" is negative", text));
    return not_a_frequency(text);
  }
  const auto d = split_decimal(text);
  if (!d || (d->unit != "Hz" && d->unit != "kHz")) return not_a_frequency(text);
  // Frequencies need not give whole periods (33Hz), so double precision is the right tool here.
  double hz = 0;
  for (char c : d->whole) hz = hz * 10 + (c - '0');
  double place = 0.1;
  for (char c : d->fraction) {
    hz += (c - '0') * place;
    place /= 10;
  }
  if (d->unit == "kHz") hz *= 1000;
  if (!(hz > 0))
    return make_error(Errc::kInvalidInput, fmt::format("\"{}\" is not a usable frequency (must be > 0)", text));
  const double period = std::round(1e9 / hz);
  if (period < 1)
    return make_error(Errc::kInvalidInput, fmt::format("\"{}\" is too high (the period is under 1ns)", text));
  return static_cast<std::int64_t>(period);
}

}  // namespace chimera
