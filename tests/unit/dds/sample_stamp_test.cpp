// The writer's stamp as a dimension label: written and read back, and anything else refused.

#include "dds/sample_stamp.hpp"

#include <gtest/gtest.h>

namespace chimera::dds_detail {
namespace {

TEST(SampleStamp, RoundTrip) {
  const SampleStamp stamp{"vision_side", 42, 1'700'000'000'123'456'789};
  const std::string label = stamp_label(stamp);
  EXPECT_EQ(label, "chimera:from=vision_side;seq=42;t=1700000000123456789");
  const auto back = parse_stamp_label(label);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->writer, "vision_side");
  EXPECT_EQ(back->sequence, 42U);
  EXPECT_EQ(back->time_ns, 1'700'000'000'123'456'789);
}

TEST(SampleStamp, OtherLabelsAreNoStamp) {
  EXPECT_FALSE(parse_stamp_label("x_m").has_value());  // a ROS 2 node's dimension label
  EXPECT_FALSE(parse_stamp_label("").has_value());
  EXPECT_FALSE(parse_stamp_label("chimera:from=a;seq=;t=1").has_value());
  EXPECT_FALSE(parse_stamp_label("chimera:from=a;seq=1x;t=1").has_value());
  EXPECT_FALSE(parse_stamp_label("chimera:from=a;t=1;seq=1").has_value());
  EXPECT_FALSE(parse_stamp_label("chimera:from=a;seq=1;t=").has_value());
}

TEST(WriterShape, RoundTrip) {
  const std::string data = shape_userdata(WriterShape{"vision_side", 6});
  EXPECT_EQ(data, "chimera:from=vision_side;type=f64;count=6");
  const auto back = parse_shape_userdata(data);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->writer, "vision_side");
  EXPECT_EQ(back->count, 6U);
}

TEST(WriterShape, OtherUserDataIsNoShape) {
  EXPECT_FALSE(parse_shape_userdata("").has_value());  // a ROS 2 node's writer
  EXPECT_FALSE(parse_shape_userdata("enclave=/;").has_value());
  EXPECT_FALSE(parse_shape_userdata("chimera:from=a;type=f64;count=").has_value());
  EXPECT_FALSE(parse_shape_userdata("chimera:from=a;type=f64;count=6x").has_value());
  EXPECT_FALSE(parse_shape_userdata("chimera:from=a;count=6").has_value());
  EXPECT_FALSE(parse_shape_userdata("chimera:from=a;type=f64;count=99999999999").has_value());
}

}  // namespace
}  // namespace chimera::dds_detail
