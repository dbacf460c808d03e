#include "chimera/net/control_gate.hpp"

#include <algorithm>

namespace chimera::net {

Reply ControlGate::execute(const Command& command) {
  std::lock_guard<std::mutex> lock(mutex_);
  Reply reply = control_.execute(command);
  feed_.observe(subsystem_);
  return reply;
}

Reply ControlGate::execute_line(std::string_view line) {
  std::lock_guard<std::mutex> lock(mutex_);
  Reply reply = control_.execute_line(line);
  feed_.observe(subsystem_);
  return reply;
}

std::string ControlGate::drain_events() {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::vector<Event> events = subsystem_.drain_events();
  feed_.observe(subsystem_, events);
  return event_lines(events);
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
      feed_.observe(subsystem_);  // what simulated time changed (a task entering ERROR), step by step
    }
    ns -= step;
  }
}

}  // namespace chimera::net
