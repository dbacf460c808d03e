// A sample's text in a stream's batched frame: what a client parses must be the value the table
// held, a non-finite double as null, a variable not written yet as null.

#include "sample_text.hpp"

#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace chimera::net {
namespace {

std::string text_of(const Result<std::vector<double>>& value) {
  std::string out;
  append_sample_value(out, value);
  return out;
}

TEST(SampleText, FiniteValuesReadBackAsTheSameDoubles) {
  const std::vector<double> values{0.0, -0.0, 1.0, -2.5, 0.1, 1.0 / 3.0, 6.02214076e23, 5e-324,
                                   std::numeric_limits<double>::max(), -std::numeric_limits<double>::min()};
  const auto parsed = nlohmann::json::parse(text_of(values));
  ASSERT_TRUE(parsed.is_array());
  ASSERT_EQ(parsed.size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(parsed[i].get<double>(), values[i]) << "element " << i;
  EXPECT_EQ(text_of(std::vector<double>{0.1, -2.5, 3.0}), "[0.1,-2.5,3]") << "the shortest text";
}

TEST(SampleText, ANonFiniteValueIsNullAsTheStatusDocumentWritesIt) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> values{1.5, nan, inf, -inf, -4.0};
  const std::string text = text_of(values);
  EXPECT_EQ(text, "[1.5,null,null,null,-4]");
  // The same as nlohmann's dump of the same array (the single-sample frame writes it that way).
  EXPECT_EQ(nlohmann::json::parse(text), nlohmann::json::parse(nlohmann::json(values).dump()));
}

TEST(SampleText, AVariableNotWrittenYetIsNullAndAnEmptyOneAnEmptyArray) {
  EXPECT_EQ(text_of(Error{Errc::kNotFound, "theta_x: not written yet"}), "null");
  EXPECT_EQ(text_of(std::vector<double>{}), "[]");
}

TEST(SampleText, SamplesAppendToOneBuffer) {
  std::string out;
  append_sample_value(out, std::vector<double>{1.0});
  out += ',';
  append_sample_value(out, Error{Errc::kNotFound, "x"});
  EXPECT_EQ(out, "[1],null");
}

}  // namespace
}  // namespace chimera::net
