#pragma once
// What the subsystem interface has to tell the operator, in one place off the real-time path:
// the events tasks put into their real-time rings (collected from there), the interface's own
// (a switch, a job overdue), and each task's last failure. Thread-safe; never used by a task's
// thread. Exported to the parts above. Not real-time safe.

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "chimera/exec/event.hpp"
#include "task_set.hpp"

namespace chimera {

/// A task's last method failure or ERROR, as its event said it.
struct TaskFailure {
  std::string text;          // "" if none
  std::int64_t time_ns = 0;  // on the subsystem's clock
  std::uint64_t number = 0;  // how many failures the task has had so far (0: none): tells one from the next
};

class EventLog {
 public:
  explicit EventLog(std::size_t tasks) : last_failure_(tasks) {}

  /// Moves every task's real-time events into the log and notes each task's last failure.
  void collect(TaskSet& tasks);
  /// An event of the interface itself.
  void add(Event event);
  /// Everything logged since the last call, oldest first.
  std::vector<Event> drain();
  /// Task `task`'s last method failure or ERROR, "" if none.
  [[nodiscard]] std::string last_error(std::size_t task) const;
  /// The same with its time and number.
  [[nodiscard]] TaskFailure last_failure(std::size_t task) const;

 private:
  mutable std::mutex mutex_;
  std::vector<Event> pending_;
  std::vector<TaskFailure> last_failure_;
};

}  // namespace chimera
