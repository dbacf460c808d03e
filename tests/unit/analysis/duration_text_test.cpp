// Durations as analysis prints them and as the profile file stores them.

#include "analysis/detail/duration_text.hpp"

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"

namespace chimera::analysis::detail {
namespace {

TEST(DurationText, ExactInTheLargestUnit) {
  EXPECT_EQ(duration_text(0), "0 ns");
  EXPECT_EQ(duration_text(999), "999 ns");
  EXPECT_EQ(duration_text(1'000), "1 µs");
  EXPECT_EQ(duration_text(35'123), "35.123 µs");
  EXPECT_EQ(duration_text(2'001'000), "2.001 ms");
  EXPECT_EQ(duration_text(2'500'000), "2.5 ms");
  EXPECT_EQ(duration_text(1'234'567), "1234.567 µs");
  EXPECT_EQ(duration_text(2'400'000'000), "2.4 s");
  EXPECT_EQ(duration_text(-3'000), "-3 µs");
}

TEST(DurationText, RoundedUpWhereExactWouldBeLong) {
  EXPECT_EQ(duration_text(1'500'000'942), "1500.001 ms");
  EXPECT_EQ(duration_text(10'000'200), "10.001 ms");  // past a 10 ms deadline, and it says so
  EXPECT_EQ(duration_text(10'000'000), "10 ms");
}

TEST(DurationText, FileStyleReadsBackExactly) {
  for (const std::int64_t ns : {1LL, 999LL, 1'000LL, 35'123LL, 2'500'000LL, 1'500'000'942LL, 7'000'000'000LL}) {
    const std::string text = duration_text(ns, DurationStyle::kFile);
    EXPECT_EQ(text.find(' '), std::string::npos) << text;
    const auto back = parse_duration_ns(text);
    ASSERT_TRUE(back) << text << ": " << back.error().message;
    EXPECT_EQ(*back, ns) << text;
  }
  EXPECT_EQ(duration_text(35'000, DurationStyle::kFile), "35us");
  EXPECT_EQ(duration_text(1'500'000'942, DurationStyle::kFile), "1500000.942us");
}

}  // namespace
}  // namespace chimera::analysis::detail
