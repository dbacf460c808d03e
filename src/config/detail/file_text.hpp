#pragma once
// Reading a subsystem file's bytes: only a regular file, and at most kMaxSubsystemFileBytes.

#include <string>

#include "chimera/core/result.hpp"

namespace chimera::config_detail {

/// The whole of `path`, if it is a regular file of at most kMaxSubsystemFileBytes (a directory,
/// a FIFO or a device is refused without reading from it, so nothing blocks or reads without
/// end). Errors carry Errc::kInvalidInput and start with the path. Not real-time safe.
Result<std::string> read_file_text(const std::string& path);

}  // namespace chimera::config_detail
