#pragma once
// Loading a subsystem file. Every problem is reported as "file:line: key: problem", and a file
// with any problem is refused whole.

#include <string>
#include <string_view>

#include "chimera/config/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "chimera/module/registry.hpp"

namespace chimera {

/// Parses "10ms", "250us", "1s", "500ns" to nanoseconds, and "100Hz", "1kHz" to a period.
Result<std::int64_t> parse_duration_ns(std::string_view text);
Result<std::int64_t> parse_frequency_period_ns(std::string_view text);

/// Loads and checks `path`: unknown keys, bad values, unknown modules or parameters, duplicate
/// or unknown task names, empty files. Errors carry Errc::kInvalidInput. Not real-time safe.
Result<SubsystemSpec> load_subsystem_file(const std::string& path, const Registry& registry);
/// The same for text already in memory; `file_name` is used in messages.
Result<SubsystemSpec> load_subsystem_text(std::string_view text, const std::string& file_name,
                                          const Registry& registry);

}  // namespace chimera
