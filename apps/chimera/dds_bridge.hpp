#pragma once
// The run's bridge to other subsystems over DDS (docs/dds.md): RemotePorts attached to the
// subsystem's table, its publisher woken by the exports' producers. The live assembly's add
// makes the table anew (a new region under the same name), and opening another file makes it
// anew for that file (its name, its exports and imports): the bridge follows it there, or its
// exports would go on publishing the old region's last values and its imports be written where
// no task reads them. A subsystem without exports or imports has the bridge idle, ready for a
// file that has some.

#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/control/remote_imports.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "chimera/dds/remote_ports.hpp"
#include "chimera/exec/write_watch.hpp"

namespace chimera::cli {

class DdsBridge {
 public:
  /// Starts the bridge for the imports and exports of `subsystem`'s file (none: idle), attached
  /// to its table (named after the file's subsystem and `shm_suffix`); refused as
  /// RemotePorts::create refuses.
  static Result<std::unique_ptr<DdsBridge>> start(Subsystem& subsystem, std::string shm_suffix);

  /// Whether the table was made anew since the bridge last attached (a task added, a file opened).
  [[nodiscard]] bool table_made_anew() const { return subsystem_.runtimes_built() != runtimes_seen_; }
  /// The bridge started again on the new table, for the subsystem's file as it is now; what it has
  /// to say of that, one line each without "dds: ". Call it where nothing changes the subsystem
  /// meanwhile (the run's loop, holding the gate).
  std::vector<std::string> follow();
  /// What the bridge has to say (an import stale or fresh again, a remote refused), one line each
  /// without "dds: ". Any time; the run's loop asks every 50 ms.
  std::vector<std::string> news();
  /// Each import of the file the bridge follows, as `status` shows it (none while idle). From the
  /// thread that drives the commands, or under the gate.
  [[nodiscard]] std::vector<RemoteImport> imports() const;
  /// The bridge's last errors; then it stops (it writes no import after this).
  std::vector<std::string> stop();

 private:
  DdsBridge(Subsystem& subsystem, std::string shm_suffix);
  /// The subsystem's file as it is now: its exports watched, then RemotePorts for its imports and
  /// exports made anew (none when it has neither).
  Result<void> attach();

  Subsystem& subsystem_;
  std::string shm_suffix_;
  std::set<std::string> watched_;  // the exports registered with the subsystem's watch
  // Registered once with the subsystem, which keeps it across rebuilds: every RemotePorts the
  // bridge makes waits on the same one.
  std::shared_ptr<WriteWatch> exports_written_ = std::make_shared<WriteWatch>();
  std::unique_ptr<RemotePorts> ports_;
  std::uint64_t runtimes_seen_ = 0;
};

}  // namespace chimera::cli
