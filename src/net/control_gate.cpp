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

std::int64_t ControlGate::fastest_writer_period_ns(const std::vector<std::string>& variables) {
  std::lock_guard<std::mutex> lock(mutex_);  // the live assembly's add and open change the tasks
  std::int64_t fastest = 0;
  for (const auto& variable : variables) {
    std::int64_t writer = 0;  // this variable's fastest periodic writer
    const auto& tasks = subsystem_.resolved().tasks;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      const ResolvedTask& task = tasks[i];
      if (subsystem_.removed(i)) continue;
      const bool writes = std::any_of(task.bindings.begin(), task.bindings.end(), [&](const PortBinding& b) {
        return b.kind == PortKind::kOutVar && b.variable == variable;
      });
      if (writes && task.spec->period_ns && (writer == 0 || *task.spec->period_ns < writer))
        writer = *task.spec->period_ns;
    }
    if (writer == 0) return 0;
    if (fastest == 0 || writer < fastest) fastest = writer;
  }
  return fastest;
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
