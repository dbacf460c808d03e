#pragma once
// Converting a variable's bytes to and from doubles, for the operator's get and set.

#include <cstddef>
#include <vector>

#include "chimera/core/result.hpp"
#include "chimera/svt/elem_type.hpp"

namespace chimera {

std::vector<double> decode_values(const VarShape& shape, const std::byte* bytes);
/// Fails if the count differs or a value does not fit the element type.
Result<std::vector<std::byte>> encode_values(const VarShape& shape, const std::vector<double>& values);

}  // namespace chimera
