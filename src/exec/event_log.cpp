#include "event_log.hpp"

#include <algorithm>
#include <cstring>

namespace chimera {

void EventLog::collect(TaskSet& tasks) {
  std::lock_guard<std::mutex> lock(mutex_);
  RtEvent e;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    while (tasks[i].events().pop(e)) {
      pending_.push_back(Event{e.time_ns, tasks[i].name(), e.text.data()});
      if (std::strstr(e.text.data(), "ERROR") != nullptr || std::strstr(e.text.data(), "failed") != nullptr) {
        TaskFailure& f = last_failure_[i];
        f = TaskFailure{e.text.data(), e.time_ns, f.number + 1};
      }
    }
  }
}

void EventLog::add(Event event) {
  std::lock_guard<std::mutex> lock(mutex_);
  pending_.push_back(std::move(event));
}

std::vector<Event> EventLog::drain() {
  std::vector<Event> out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    out.swap(pending_);
  }
  std::stable_sort(out.begin(), out.end(), [](const Event& a, const Event& b) { return a.time_ns < b.time_ns; });
  return out;
}

std::string EventLog::last_error(std::size_t task) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_failure_[task].text;
}

TaskFailure EventLog::last_failure(std::size_t task) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_failure_[task];
}

}  // namespace chimera
