#pragma once
// Reading an input file's bytes (a subsystem file, a profile): only a regular file, and at most
// kMaxSubsystemFileBytes.

#include <string>
#include <string_view>

#include "chimera/core/result.hpp"

namespace chimera::config_detail {

/// The whole of `path`, if it is a regular file of at most kMaxSubsystemFileBytes (a directory,
/// a FIFO or a device is refused without reading from it, so nothing blocks or reads without
/// end). Errors carry Errc::kInvalidInput, start with the path and call the file `what`.
/// Not real-time safe.
Result<std::string> read_file_text(const std::string& path, std::string_view what = "subsystem file");

}  // namespace chimera::config_detail
