#pragma once
// Reading the subsystem file's `requests:` list: the switches that tasks may ask for. Private to
// src/config.

#include <optional>

#include "chimera/config/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "name_index.hpp"
#include "yaml_reader.hpp"

namespace chimera::config_detail {

/// The names of a file's tasks and configurations, once read, for the checks of what follows.
struct FileNames {
  NameIndex tasks;
  NameIndex configurations;
};

/// Reads `requests:` (absent: none allowed) into spec.requests. Configurations and tasks must
/// already be read (`names` holds them): every name is checked against them.
Result<void> read_requests(const Source& source, const std::optional<Field>& field, const FileNames& names,
                           SubsystemSpec& spec);

}  // namespace chimera::config_detail
