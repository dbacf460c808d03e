// Durations as analysis prints them and as the profile file stores them; and as tables show them.

#include "chimera/core/duration_text.hpp"

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"

namespace chimera {
namespace {

TEST(DurationText, ExactInTheLargestUnit) {
  EXPECT_EQ(exact_duration_text(0), "0 ns");
  EXPECT_EQ(exact_duration_text(999), "999 ns");
  EXPECT_EQ(exact_duration_text(1'000), "1 µs");
  EXPECT_EQ(exact_duration_text(35'123), "35.123 µs");
  EXPECT_EQ(exact_duration_text(2'001'000), "2.001 ms");
  EXPECT_EQ(exact_duration_text(2'500'000), "2.5 ms");
  EXPECT_EQ(exact_duration_text(1'234'567), "1234.567 µs");
  EXPECT_EQ(exact_duration_text(2'400'000'000), "2.4 s");
  EXPECT_EQ(exact_duration_text(-3'000), "-3 µs");
}

TEST(DurationText, RoundedUpWhereExactWouldBeLong) {
  EXPECT_EQ(exact_duration_text(1'500'000'942), "1500.001 ms");
  EXPECT_EQ(exact_duration_text(10'000'200), "10.001 ms");  // past a 10 ms deadline, and it says so
  EXPECT_EQ(exact_duration_text(10'000'000), "10 ms");
}

TEST(DurationText, FileStyleReadsBackExactly) {
  for (const std::int64_t ns : {1LL, 999LL, 1'000LL, 35'123LL, 2'500'000LL, 1'500'000'942LL, 7'000'000'000LL}) {
    const std::string text = exact_duration_text(ns, DurationStyle::kFile);
    EXPECT_EQ(text.find(' '), std::string::npos) << text;
    const auto back = parse_duration_ns(text);
    ASSERT_TRUE(back) << text << ": " << back.error().message;
    EXPECT_EQ(*back, ns) << text;
  }
  EXPECT_EQ(exact_duration_text(35'000, DurationStyle::kFile), "35us");
  EXPECT_EQ(exact_duration_text(1'500'000'942, DurationStyle::kFile), "1500000.942us");
}

TEST(FormatDuration, PicksTheUnitThatKeepsTheNumberShort) {
  EXPECT_EQ(format_duration(0), "0 ns");
  EXPECT_EQ(format_duration(850), "850 ns");
  EXPECT_EQ(format_duration(12'345), "12.3 µs");
  EXPECT_EQ(format_duration(999'949), "999.9 µs");
  EXPECT_EQ(format_duration(1'250'000), "1.25 ms");
  EXPECT_EQ(format_duration(2'000'000'000), "2.000 s");
}

TEST(FormatPeriod, ReadsAsTheFileWroteIt) {
  EXPECT_EQ(format_period(0), "aperiodic");
  EXPECT_EQ(format_period(1'000'000), "1 ms");
  EXPECT_EQ(format_period(30'000'000), "30 ms");
  EXPECT_EQ(format_period(250'000), "250 µs");
  EXPECT_EQ(format_period(2'000'000'000), "2 s");
  EXPECT_EQ(format_period(30'303'030), "30.303 ms");  // 33Hz
  EXPECT_EQ(format_period(500), "500 ns");
}

}  // namespace
}  // namespace chimera
