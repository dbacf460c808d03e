#include "chimera/net/control_gate.hpp"

#include <algorithm>

namespace chimera::net {

Reply ControlGate::execute(const Command& command) {
  std::lock_guard<std::mutex> lock(mutex_);
  return control_.execute(command);
}

Reply ControlGate::execute_line(std::string_view line) {
  std::lock_guard<std::mutex> lock(mutex_);
  return control_.execute_line(line);
}

std::string ControlGate::drain_events() {
  std::lock_guard<std::mutex> lock(mutex_);
  return control_.drain_events();
}

void ControlGate::run_for(std::int64_t ns) {
  if (subsystem_.clock() == ClockKind::kReal) {
    subsystem_.run_for(ns);  // a sleep: the tasks run on their own threads meanwhile
    return;
  }
  while (ns > 0) {
    const std::int64_t step = std::min(ns, kStepNs);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      subsystem_.run_for(step);
    }
    ns -= step;
  }
}

}  // namespace chimera::net
