#pragma once
// The subsystem's resource ports to other subsystems (paper 3.3): its `exports:` published and its
// `imports:` read over Cyclone DDS (docs/dds.md). The bridge attaches to the subsystem's global
// table like any task and runs on two ordinary threads of its own, one publishing and one taking
// samples: no DDS call runs on a real-time thread, and a stalled network slows only the bridge.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "chimera/exec/write_watch.hpp"

namespace chimera {

struct RemotePortsOptions {
  /// How often the publishing thread looks for new values of the exports, at the least.
  std::int64_t poll_ns = 1'000'000;
  /// Woken by the exports' producers (Subsystem::watch_writes): the publishing thread then
  /// publishes at once rather than at its next poll. None: the poll alone.
  std::shared_ptr<WriteWatch> exports_written;
  /// Raise the illegal-configuration flag while any import is stale, so that the robot
  /// interfaces hold the arm (paper 3.4) when the machine that feeds them drops off.
  bool hold_when_stale = true;
};

/// What the bridge knows of one import.
struct ImportStatus {
  std::string variable;
  std::uint64_t samples = 0;          // written into the table so far
  std::uint64_t refused = 0;          // samples of the wrong size, never written
  std::string writer;                 // the last writer's subsystem, "" without a Chimera stamp
  std::uint64_t writer_sequence = 0;  // its sequence number (0 without a stamp)
  std::int64_t writer_time_ns = 0;    // its wall-clock time when it wrote: not comparable to ours
  bool stale = true;                  // not written within max_age (nor ever, at first)
  std::int64_t age_ns = -1;           // since the last sample was written (our clock); -1: none yet
  std::int64_t max_age_ns = 0;        // its file's max_age
  std::string refusal;                // the last remote writer refused for it (size, type), "" if none
};

class RemotePorts {
 public:
  /// Attaches to the global table `table_name` (the subsystem's name and any shm suffix, as
  /// GlobalTable::attach takes it), makes the DDS participant on spec.dds, one writer per export
  /// and one reader per import (topic "rt/VAR", type std_msgs/msg/Float64MultiArray, keep last
  /// 1), and starts both threads. Every export and import must be a variable of the table with
  /// the shape verification gave it. Not real-time safe.
  static Result<std::unique_ptr<RemotePorts>> create(const SubsystemSpec& spec, std::string_view table_name,
                                                     RemotePortsOptions options = {});
  /// Stops both threads, then removes the DDS entities and lowers any hold of the flag.
  ~RemotePorts();
  RemotePorts(const RemotePorts&) = delete;
  RemotePorts& operator=(const RemotePorts&) = delete;

  /// Each import, in file order. Any thread; not real-time safe.
  [[nodiscard]] std::vector<ImportStatus> imports() const;
  /// Problems seen since the last call, one line each, oldest first: a remote writer of the wrong
  /// size (named, with both ends' shapes, once per writer and variable: at its discovery when it
  /// is a Chimera subsystem, else at its first sample), a remote writer of another type on an
  /// import's topic (at its discovery: DDS never delivers its samples), a second exporter of a
  /// variable (eq. 1).
  /// Not real-time safe.
  [[nodiscard]] std::vector<std::string> take_errors();
  /// What changed since the last call, one line each, oldest first: an import's first sample, an
  /// import gone stale (past max_age), fresh again. Not real-time safe.
  [[nodiscard]] std::vector<std::string> take_changes();

  struct Impl;

 private:
  explicit RemotePorts(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace chimera
