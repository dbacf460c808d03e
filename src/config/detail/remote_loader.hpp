#pragma once
// Reading the subsystem file's `exports:`, `imports:` and `dds:`: the state variables shared with
// other subsystems over DDS (contract section 4). Private to src/config.

#include <optional>

#include "chimera/config/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "yaml_reader.hpp"

namespace chimera::config_detail {

/// Reads `exports:` (absent: none) into spec.exports.
Result<void> read_exports(const Source& source, const std::optional<Field>& field, SubsystemSpec& spec);
/// Reads `imports:` (absent: none) into spec.imports; exports must be read first (a variable is
/// either exported or imported, never both).
Result<void> read_imports(const Source& source, const std::optional<Field>& field, SubsystemSpec& spec);
/// Reads `dds:` (absent: domain 0, the default partition) into spec.dds.
Result<void> read_dds(const Source& source, const std::optional<Field>& field, SubsystemSpec& spec);

}  // namespace chimera::config_detail
