#pragma once
// Loading a subsystem file. Every problem is reported as "file:line: key: problem", and a file
// with any problem is refused whole.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "chimera/module/registry.hpp"

namespace chimera {

/// Parses "10ms", "250us", "1s", "500ns", "2.5ms" (no space, not negative, at most 1ns
/// resolution) to nanoseconds, and "100Hz", "1kHz", "33.3Hz" to a period rounded to 1ns.
/// Zero durations are accepted; callers that need a positive one check it. Not real-time safe.
Result<std::int64_t> parse_duration_ns(std::string_view text);
Result<std::int64_t> parse_frequency_period_ns(std::string_view text);

/// The largest subsystem file read (4 MiB: tens of thousands of tasks). A larger file, or text,
/// is refused with a message before it is parsed, so that loading takes time and memory in
/// proportion to what may be read.
inline constexpr std::size_t kMaxSubsystemFileBytes = std::size_t{4} << 20;

/// Loads and checks `path`, which must be a regular file (a directory, FIFO or device is refused
/// unread) of at most kMaxSubsystemFileBytes: unknown keys, bad values, unknown modules or parameters, duplicate
/// or unknown task names, empty files. Errors carry Errc::kInvalidInput. Not real-time safe.
Result<SubsystemSpec> load_subsystem_file(const std::string& path, const Registry& registry);
/// The same for text already in memory; `file_name` is used in messages.
Result<SubsystemSpec> load_subsystem_text(std::string_view text, const std::string& file_name,
                                          const Registry& registry);

/// One entry of a subsystem file's `plugins:` list, with where it is written.
struct PluginRef {
  std::string name;  // as written: a library file name, or a path
  int line = 0;
  std::string key;  // "plugins[0]"
};

/// Only the `plugins:` list of a subsystem file, so that a caller can load the module libraries
/// it names before load_subsystem_file() checks the tasks' modules against the registry
/// (load_file_plugins() in chimera/config/plugins.hpp does both steps for a file).
/// Errors carry Errc::kInvalidInput. Not real-time safe.
Result<std::vector<PluginRef>> read_plugin_names_file(const std::string& path);
/// The same for text already in memory; `file_name` is used in messages.
Result<std::vector<PluginRef>> read_plugin_names_text(std::string_view text, const std::string& file_name);

}  // namespace chimera
