#pragma once
// What the subsystem interface has to tell the operator, in one place off the real-time path:
// the events tasks put into their real-time rings (collected from there), the interface's own
// (a switch, a job overdue), and each task's last failure. Thread-safe; never used by a task's
// thread. Exported to the parts above. Not real-time safe.

#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

#include "chimera/exec/event.hpp"
#include "task_set.hpp"

namespace chimera {

class EventLog {
 public:
  explicit EventLog(std::size_t tasks) : last_error_(tasks) {}

  /// Moves every task's real-time events into the log and notes each task's last failure.
  void collect(TaskSet& tasks);
  /// An event of the interface itself.
  void add(Event event);
  /// Everything logged since the last call, oldest first.
  std::vector<Event> drain();
  /// Task `task`'s last method failure or ERROR, "" if none.
  [[nodiscard]] std::string last_error(std::size_t task) const;

 private:
  mutable std::mutex mutex_;
  std::vector<Event> pending_;
  std::vector<std::string> last_error_;
};

}  // namespace chimera
