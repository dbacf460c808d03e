#pragma once
// Reading one entry of the subsystem file's `tasks:` list. Private to src/config.

#include "chimera/config/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "chimera/module/registry.hpp"
#include "name_index.hpp"
#include "yaml_reader.hpp"

namespace chimera::config_detail {

/// Reads and checks one task: its keys, a name not in `earlier_tasks` (the names read so far,
/// with their lines), timing, module, parameters (checked against the module's declarations,
/// defaults filled in) and renames. `file.cpus` must already be read.
Result<TaskSpec> load_task(const Source& source, const Field& task, const SubsystemSpec& file,
                           const NameIndex& earlier_tasks, const Registry& registry);

}  // namespace chimera::config_detail
