#pragma once
// The one rule for the names of modules, ports, parameters and tasks: letters, digits and '_',
// not starting with a digit (so that a name reads the same in YAML, C, C++ and a URL).

#include <string_view>

namespace chimera {

/// Whether `text` is a valid name. Real-time safe.
[[nodiscard]] bool is_identifier(std::string_view text) noexcept;

}  // namespace chimera
