#include "chimera/svt/value_codec.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>

#include <fmt/format.h>

namespace chimera {

namespace {
template <class T>
T load(const std::byte* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}
template <class T>
void put(std::byte* p, T v) {
  std::memcpy(p, &v, sizeof(T));
}
}  // namespace

std::vector<double> decode_values(const VarShape& shape, const std::byte* bytes) {
  std::vector<double> out(shape.count);
  const std::size_t w = elem_size(shape.type);
  for (std::size_t i = 0; i < shape.count; ++i) {
    const std::byte* p = bytes + i * w;
    switch (shape.type) {
      case ElemType::kF64: out[i] = load<double>(p); break;
      case ElemType::kF32: out[i] = load<float>(p); break;
      case ElemType::kI64: out[i] = static_cast<double>(load<std::int64_t>(p)); break;
      case ElemType::kI32: out[i] = load<std::int32_t>(p); break;
      case ElemType::kU8: out[i] = load<std::uint8_t>(p); break;
    }
  }
  return out;
}

Result<std::vector<std::byte>> encode_values(const VarShape& shape, const std::vector<double>& values) {
  if (values.size() != shape.count)
    return make_error(Errc::kInvalidInput, fmt::format("expected {} value{} ({}), got {}", shape.count,
                                                       shape.count == 1 ? "" : "s", to_string(shape), values.size()));
  std::vector<std::byte> out(shape.bytes());
  const std::size_t w = elem_size(shape.type);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    std::byte* p = out.data() + i * w;
    const bool integral = shape.type != ElemType::kF64 && shape.type != ElemType::kF32;
    if (integral && v != std::floor(v))
      return make_error(Errc::kInvalidInput, fmt::format("{} is not a whole number ({})", v, elem_name(shape.type)));
    switch (shape.type) {
      case ElemType::kF64: put(p, v); break;
      case ElemType::kF32: put(p, static_cast<float>(v)); break;
      case ElemType::kI64: put(p, static_cast<std::int64_t>(v)); break;
      case ElemType::kI32:
        if (std::abs(v) > 2147483647.0) return make_error(Errc::kInvalidInput, fmt::format("{} does not fit i32", v));
        put(p, static_cast<std::int32_t>(v));
        break;
      case ElemType::kU8:
        if (v < 0 || v > 255) return make_error(Errc::kInvalidInput, fmt::format("{} does not fit u8", v));
        put(p, static_cast<std::uint8_t>(v));
        break;
    }
  }
  return out;
}

}  // namespace chimera
