#pragma once
// The module libraries a subsystem file names in `plugins:`, loaded before the file's tasks are
// checked against the module library. Not real-time safe, not thread-safe.

#include <string>
#include <vector>

#include "chimera/core/result.hpp"
#include "chimera/module/plugin_loader.hpp"

namespace chimera {

/// Finds (on CHIMERA_MODULE_PATH; a relative path from the file's directory) and loads each
/// library of the `plugins:` list of `path`, in order. The first problem is reported as
/// "file:line: plugins[i]: problem", e.g. "arm.yaml:3: plugins[0]: cannot load 'libx.so': ...".
/// Errors carry Errc::kInvalidInput.
Result<std::vector<LoadedPlugin>> load_file_plugins(const std::string& path);

}  // namespace chimera
