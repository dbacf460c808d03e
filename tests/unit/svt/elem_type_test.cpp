#include "chimera/svt/elem_type.hpp"

#include <gtest/gtest.h>

namespace chimera {
namespace {

TEST(ElemType, ParsesEveryName) {
  EXPECT_EQ(parse_elem_type("f64"), ElemType::kF64);
  EXPECT_EQ(parse_elem_type("f32"), ElemType::kF32);
  EXPECT_EQ(parse_elem_type("i64"), ElemType::kI64);
  EXPECT_EQ(parse_elem_type("i32"), ElemType::kI32);
  EXPECT_EQ(parse_elem_type("u8"), ElemType::kU8);
  EXPECT_EQ(parse_elem_type("bool"), ElemType::kU8);  // bool travels as one byte
}

TEST(ElemType, RejectsUnknownNames) {
  EXPECT_FALSE(parse_elem_type(""));
  EXPECT_FALSE(parse_elem_type("F64"));
  EXPECT_FALSE(parse_elem_type("f16"));
  EXPECT_FALSE(parse_elem_type("double"));
  EXPECT_FALSE(parse_elem_type("f64 "));
}

TEST(ElemType, NamesRoundTrip) {
  for (ElemType t : {ElemType::kF64, ElemType::kF32, ElemType::kI64, ElemType::kI32, ElemType::kU8}) {
    EXPECT_EQ(parse_elem_type(elem_name(t)), t);
  }
}

TEST(ElemType, SizesMatchTheCTypes) {
  EXPECT_EQ(elem_size(ElemType::kF64), sizeof(double));
  EXPECT_EQ(elem_size(ElemType::kF32), sizeof(float));
  EXPECT_EQ(elem_size(ElemType::kI64), sizeof(std::int64_t));
  EXPECT_EQ(elem_size(ElemType::kI32), sizeof(std::int32_t));
  EXPECT_EQ(elem_size(ElemType::kU8), 1U);
  static_assert(kElemTypeOf<double> == ElemType::kF64);
  static_assert(kElemTypeOf<float> == ElemType::kF32);
  static_assert(kElemTypeOf<std::int64_t> == ElemType::kI64);
  static_assert(kElemTypeOf<std::int32_t> == ElemType::kI32);
  static_assert(kElemTypeOf<std::uint8_t> == ElemType::kU8);
  static_assert(kElemTypeOf<bool> == ElemType::kU8);
}

TEST(VarShape, PrintsTypeAndCount) {
  EXPECT_EQ(to_string(VarShape{ElemType::kF64, 6}), "f64[6]");
  EXPECT_EQ(to_string(VarShape{ElemType::kU8, 1}), "u8[1]");
  EXPECT_EQ(to_string(VarShape{ElemType::kI32, 1024}), "i32[1024]");
}

TEST(VarShape, BytesAndEquality) {
  EXPECT_EQ((VarShape{ElemType::kF32, 3}.bytes()), 12U);
  EXPECT_EQ((VarShape{ElemType::kF64, 6}), (VarShape{ElemType::kF64, 6}));
  EXPECT_NE((VarShape{ElemType::kF64, 6}), (VarShape{ElemType::kF64, 3}));
  EXPECT_NE((VarShape{ElemType::kF64, 6}), (VarShape{ElemType::kI64, 6}));
}

}  // namespace
}  // namespace chimera
