#pragma once
// Helpers the modules of the library share. None is real-time safe: they are for init.

#include <cstddef>
#include <string>
#include <string_view>

#include "chimera/module/params.hpp"

namespace chimera::modules {

/// A message for Status::fail built at init (with a path or a count), kept for the life of the
/// program: Status carries only static strings. Each distinct message is stored once.
const char* intern(std::string message);

/// A per-joint parameter: its n values, or one value for every joint. Empty when it has another
/// length or a value that is not finite.
Vector per_joint(const Params& p, std::string_view name, Vector fallback, std::size_t n);

/// Whether every value is >= 0 (per_joint() leaves the sign to the caller).
bool all_non_negative(const Vector& v);

/// Where a log file of a module is: `file` itself, or below $CHIMERA_LOG_DIR (when it is set) if
/// `file` is relative. data_logger writes there and log_player reads there.
std::string log_file_path(const std::string& file);

}  // namespace chimera::modules
