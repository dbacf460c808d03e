#include "chimera/svt/elem_type.hpp"

#include <fmt/format.h>

namespace chimera {

std::optional<ElemType> parse_elem_type(std::string_view name) {
  if (name == "f64") return ElemType::kF64;
  if (name == "f32") return ElemType::kF32;
  if (name == "i64") return ElemType::kI64;
  if (name == "i32") return ElemType::kI32;
  // bool has no element type of its own: it travels as one byte, 0 or 1.
  if (name == "u8" || name == "bool") return ElemType::kU8;
  return std::nullopt;
}

std::string to_string(const VarShape& shape) { return fmt::format("{}[{}]", elem_name(shape.type), shape.count); }

}  // namespace chimera
