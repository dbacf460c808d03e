// Durations and frequencies of the subsystem file.

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"

namespace chimera {
namespace {

std::int64_t ns(std::string_view text) {
  auto r = parse_duration_ns(text);
  EXPECT_TRUE(r.ok()) << text << ": " << (r.ok() ? "" : r.error().message);
  return r.ok() ? *r : -1;
}

std::int64_t period(std::string_view text) {
  auto r = parse_frequency_period_ns(text);
  EXPECT_TRUE(r.ok()) << text << ": " << (r.ok() ? "" : r.error().message);
  return r.ok() ? *r : -1;
}

TEST(ParseDuration, EveryUnit) {
  EXPECT_EQ(ns("500ns"), 500);
  EXPECT_EQ(ns("250us"), 250'000);
  EXPECT_EQ(ns("10ms"), 10'000'000);
  EXPECT_EQ(ns("1s"), 1'000'000'000);
}

TEST(ParseDuration, DecimalsAreExact) {
  EXPECT_EQ(ns("2.5ms"), 2'500'000);
  EXPECT_EQ(ns("0.001s"), 1'000'000);
  EXPECT_EQ(ns("1.5us"), 1'500);
  EXPECT_EQ(ns("0.000000001s"), 1);
  EXPECT_EQ(ns("3.10ms"), 3'100'000);  // trailing zeros add no precision
  EXPECT_EQ(ns("7.0ns"), 7);
}

TEST(ParseDuration, ZeroIsADuration) {
  EXPECT_EQ(ns("0ms"), 0);
  EXPECT_EQ(ns("0ns"), 0);
}

TEST(ParseDuration, LargestValues) {
  EXPECT_EQ(ns("9223372036s"), 9'223'372'036'000'000'000);
  EXPECT_FALSE(parse_duration_ns("9223372037s").ok());
  EXPECT_FALSE(parse_duration_ns("99999999999999999999999ns").ok());
}

TEST(ParseDuration, RejectsBadForms) {
  for (const char* bad : {"", "10", "ms", "10 ms", " 10ms", "10ms ", "10MS", "10sec", "10m", "1.ms", ".5ms", "1e3ms",
                          "+10ms", "10msx", "1,5ms", "10Hz", "abc"}) {
    auto r = parse_duration_ns(bad);
    ASSERT_FALSE(r.ok()) << "accepted \"" << bad << "\"";
    EXPECT_EQ(r.error().code, Errc::kInvalidInput);
  }
}

TEST(ParseDuration, MessageNamesTheUnits) {
  auto r = parse_duration_ns("10 ms");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "\"10 ms\" is not a duration (use ns, us, ms or s, e.g. 10ms)");
}

TEST(ParseDuration, RejectsNegatives) {
  auto r = parse_duration_ns("-5ms");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "\"-5ms\" is negative; a duration is >= 0");
}

TEST(ParseDuration, RejectsBelowOneNanosecond) {
  auto r = parse_duration_ns("1.5ns");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "\"1.5ns\" is finer than the 1ns resolution");
  EXPECT_FALSE(parse_duration_ns("0.0000000001s").ok());
}

TEST(ParseFrequency, HzAndKhz) {
  EXPECT_EQ(period("100Hz"), 10'000'000);
  EXPECT_EQ(period("1kHz"), 1'000'000);
  EXPECT_EQ(period("1Hz"), 1'000'000'000);
  EXPECT_EQ(period("2.5kHz"), 400'000);
  EXPECT_EQ(period("33Hz"), 30'303'030);  // rounded to the nearest nanosecond
}

TEST(ParseFrequency, RejectsBadForms) {
  for (const char* bad :
       {"", "100", "100 Hz", "100hz", "100HZ", "1MHz", "10ms", "Hz", "-5Hz", "0Hz", "0.0kHz", "3000000000Hz"}) {
    auto r = parse_frequency_period_ns(bad);
    ASSERT_FALSE(r.ok()) << "accepted \"" << bad << "\"";
    EXPECT_EQ(r.error().code, Errc::kInvalidInput);
  }
  auto r = parse_frequency_period_ns("100 Hz");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "\"100 Hz\" is not a frequency (use Hz or kHz, e.g. 100Hz)");
}

}  // namespace
}  // namespace chimera
