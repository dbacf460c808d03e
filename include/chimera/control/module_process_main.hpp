#pragma once
// The body of a module process (docs/processes.md): what `chimera __worker` runs once it has loaded
// the file. It attaches to the subsystem's global table and to the task block it inherited, runs
// the tasks of its process under the real executive, and carries out the main process's commands
// from its socket until told to quit (or until the main process is gone). Not real-time safe.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/module/registry.hpp"

namespace chimera {

struct ModuleProcessArgs {
  std::string process;                             // the name of the process whose tasks it runs
  std::string table;                               // the global table's subsystem name (with the run's suffix)
  int socket_fd = -1;                              // the command socket
  int block_fd = -1;                               // the task block's memfd
  int life = -1;                                   // its life lock in the task block (held while it lives); -1: none
  int history_fd = -1;                             // the flight recorder's shared rings (a memfd); -1: none kept
  double record_seconds = 0;                       // the history the main process laid those rings out for
  std::vector<std::pair<std::size_t, int>> bells;  // the aperiodic tasks' eventfds (task, fd), the main process's
  std::optional<std::string> configuration;        // the start configuration (the first plan)
  bool realtime_priorities = true;
  bool measure_cpu_time = false;
  bool rt_check = false;
};

/// Runs the module process; returns its exit code (0 after a quit). Not real-time safe.
int run_module_process(const SubsystemSpec& spec, const Registry& registry, const ModuleProcessArgs& args);

}  // namespace chimera
