#pragma once
// The run's bridge to other subsystems over DDS (docs/dds.md): RemotePorts attached to the
// subsystem's table, its publisher woken by the exports' producers. The live assembly's add
// makes the table anew (a new region under the same name); the bridge follows it there, or its
// exports would go on publishing the old region's last values and its imports be written where
// no task reads them.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "chimera/dds/remote_ports.hpp"
#include "chimera/exec/write_watch.hpp"

namespace chimera::cli {

class DdsBridge {
 public:
  /// Attaches to `subsystem`'s table (`table_name`: its name and shm suffix) and starts the
  /// bridge for `spec`'s imports and exports; refused as RemotePorts::create refuses.
  static Result<std::unique_ptr<DdsBridge>> start(const SubsystemSpec& spec, Subsystem& subsystem,
                                                  std::string table_name);

  /// What the bridge has to say (an import stale or fresh again, a remote refused), one line each
  /// without "dds: "; first, if the table was made anew since the last call, the bridge is started
  /// again on the new one (and says so, or why it could not be). Call it from the run's loop.
  std::vector<std::string> poll();
  /// The bridge's last errors; then it stops (it writes no import after this).
  std::vector<std::string> stop();

 private:
  DdsBridge(const SubsystemSpec& spec, Subsystem& subsystem, std::string table_name);
  Result<void> attach();

  SubsystemSpec spec_;
  Subsystem& subsystem_;
  std::string table_name_;
  // Registered once with the subsystem, which keeps it across rebuilds: every RemotePorts the
  // bridge makes waits on the same one.
  std::shared_ptr<WriteWatch> exports_written_ = std::make_shared<WriteWatch>();
  std::unique_ptr<RemotePorts> ports_;
  std::uint64_t runtimes_seen_ = 0;
};

}  // namespace chimera::cli
