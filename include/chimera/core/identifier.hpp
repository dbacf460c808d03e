#pragma once
// The one rule for the names of modules, ports, parameters and tasks: letters, digits and '_',
// not starting with a digit (so that a name reads the same in YAML, C, C++ and a URL).

#include <cstddef>
#include <string_view>

namespace chimera {

/// Whether `text` is a valid name. Real-time safe.
[[nodiscard]] bool is_identifier(std::string_view text) noexcept;

/// The longest state variable name: a variable's name lives in a fixed field of the table's
/// shared memory (64 bytes with its NUL), so the loader refuses a longer one at its line rather
/// than `run` refusing it later without one.
inline constexpr std::size_t kMaxVariableName = 63;

}  // namespace chimera
