#pragma once
// What a subsystem's imports from other subsystems are doing (docs/dds.md), for `status` in the
// shell and the network API. The bridge that takes them (Cyclone DDS) lives above the control
// part and outside the library: it hands the subsystem a function that reports them, and the
// subsystem interface shows them beside its tasks without knowing DDS.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace chimera {

/// One import as the operator sees it.
struct RemoteImport {
  std::string variable;
  std::string writer;           // the last writer's subsystem, "" without a Chimera stamp
  std::uint64_t samples = 0;    // written into the table so far
  std::uint64_t refused = 0;    // samples of the wrong size, never written
  std::int64_t age_ns = -1;     // since the last sample was written, on the bridge's clock; -1: none yet
  std::int64_t max_age_ns = 0;  // older than this: stale
  bool stale = true;            // no sample within max_age (nor ever, at first)
  std::string refusal;          // the last remote refused for it (size, type), "" if none
};

/// Called under the subsystem's command gate, from the thread that carries out a command; not
/// real-time safe.
using RemoteImportsReport = std::function<std::vector<RemoteImport>()>;

/// The imports as a table for `status`: one row each, "" for none.
std::string remote_imports_table(const std::vector<RemoteImport>& imports);

}  // namespace chimera
