#pragma once
// Loading the subsystem file a subcommand was given, with the messages every subcommand prints.

#include <optional>
#include <string>

#include "chimera/config/subsystem.hpp"

namespace chimera::cli {

/// Loads the module libraries of `file`'s `plugins:` list, then `file` against the global
/// registry, and checks that `config`, if given, names one of its configurations. On a problem prints the one message
/// to stderr and returns nothing (the caller exits with kExitInvalid).
std::optional<SubsystemSpec> load_file(const std::string& file, const std::optional<std::string>& config);

}  // namespace chimera::cli
