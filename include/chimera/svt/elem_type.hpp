#pragma once
// Element types of state variables and the shape (type, count) of one variable.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace chimera {

/// The element type of a state variable. bool travels as u8.
enum class ElemType : std::uint8_t { kF64, kF32, kI64, kI32, kU8 };

/// Bytes of one element. Real-time safe.
constexpr std::size_t elem_size(ElemType t) noexcept {
  switch (t) {
    case ElemType::kF64:
    case ElemType::kI64: return 8;
    case ElemType::kF32:
    case ElemType::kI32: return 4;
    case ElemType::kU8: return 1;
  }
  return 0;
}

/// The name used in files and messages: f64, f32, i64, i32, u8.
constexpr std::string_view elem_name(ElemType t) noexcept {
  switch (t) {
    case ElemType::kF64: return "f64";
    case ElemType::kF32: return "f32";
    case ElemType::kI64: return "i64";
    case ElemType::kI32: return "i32";
    case ElemType::kU8: return "u8";
  }
  return "?";
}

/// Parses f64, f32, i64, i32, u8 or bool.
std::optional<ElemType> parse_elem_type(std::string_view name);

template <class T>
struct ElemTypeOf;
template <>
struct ElemTypeOf<double> {
  static constexpr ElemType kValue = ElemType::kF64;
};
template <>
struct ElemTypeOf<float> {
  static constexpr ElemType kValue = ElemType::kF32;
};
template <>
struct ElemTypeOf<std::int64_t> {
  static constexpr ElemType kValue = ElemType::kI64;
};
template <>
struct ElemTypeOf<std::int32_t> {
  static constexpr ElemType kValue = ElemType::kI32;
};
template <>
struct ElemTypeOf<std::uint8_t> {
  static constexpr ElemType kValue = ElemType::kU8;
};
template <>
struct ElemTypeOf<bool> {
  static constexpr ElemType kValue = ElemType::kU8;
};

/// The element type that stores T; only the five types above compile.
template <class T>
inline constexpr ElemType kElemTypeOf = ElemTypeOf<T>::kValue;

/// What a producer and a consumer must agree on (rule 3).
struct VarShape {
  ElemType type = ElemType::kF64;
  std::uint32_t count = 1;

  [[nodiscard]] constexpr std::size_t bytes() const noexcept { return elem_size(type) * count; }
  friend constexpr bool operator==(const VarShape&, const VarShape&) = default;
};

/// "f64[6]".
std::string to_string(const VarShape& shape);

/// A variable of the global table: its name and shape.
struct VarSpec {
  std::string name;
  VarShape shape;
};

}  // namespace chimera
