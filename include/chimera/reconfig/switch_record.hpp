#pragma once
// What the subsystem interface reports of one dynamic reconfiguration (paper 3.4).

#include <cstdint>
#include <string>
#include <vector>

namespace chimera {

struct SwitchRecord {
  std::string from;
  std::string to;
  std::string cause;                 // "operator", or "requested by TASK"
  std::int64_t requested_ns = 0;     // subsystem clock: when it was asked for
  std::int64_t committed_ns = 0;     // when the new configuration took over
  std::vector<std::string> off;      // tasks that left (turned off)
  std::vector<std::string> on;       // tasks that joined (turned on)
  std::vector<std::string> spawned;  // tasks created for it (init), in the background
  std::vector<std::string> reinit;   // tasks whose in-consts changed value: reinit() before their next cycle
  bool flag_raised = false;          // the illegal-configuration flag was up while it lasted
};

/// One line: "at 5.002 s: switch standard -> near_singularity (requested by monitor): off ik; on
/// dls, integ; created dls, integ; committed after 1.00 ms, ...".
std::string describe(const SwitchRecord& record);

}  // namespace chimera
