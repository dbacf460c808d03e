// The overrun watch (real clock): a job still running past its deadline. end_job counts a missed
// deadline when the job ends; a job stuck in cycle() may never end, and a hard task's
// error() cannot run on a thread that is still inside cycle(). So the subsystem's service
// thread looks at every task's running job each kWatchTickNs: a job more than a tick past its
// deadline is reported once, and while any hard task has one the illegal-configuration flag stays
// up, so that the robot interfaces hold still. Once the job ends, end_job's own handling follows
// (error(), then ERROR if it does not recover). Not on any task's real-time path.

#include <fmt/format.h>

#include "subsystem_impl.hpp"

namespace chimera {

void Subsystem::Impl::watch_overruns() {
  const std::int64_t now = real_exec->now_ns();
  int hard = 0;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const std::optional<std::int64_t> deadline = real_exec->running_deadline(i);
    if (!deadline || now <= *deadline + kWatchTickNs) continue;
    const Task& t = *tasks[i];
    if (t.hard()) ++hard;
    if (overdue_reported[i] == *deadline) continue;  // this job is reported already
    overdue_reported[i] = *deadline;
    const double late_ms = static_cast<double>(now - *deadline) / 1e6;
    const double released_s = static_cast<double>(*deadline - t.spec().deadline_ns) / 1e9;
    std::lock_guard<std::mutex> lock(events_mutex);
    pending.push_back(Event{
        now, t.name(),
        t.hard() ? fmt::format("still running {:.1f} ms past its deadline (released at {:.3f} s): a cycle that does "
                               "not return? The illegal-configuration flag is up until it ends",
                               late_ms, released_s)
                 : fmt::format("still running {:.1f} ms past its deadline (released at {:.3f} s): a cycle that does "
                               "not return? Soft: counted as a miss when it ends",
                               late_ms, released_s)});
  }
  hard_overdue.store(hard, std::memory_order_relaxed);  // relaxed: update_flag reads it next, under its mutex
  update_flag();
}

}  // namespace chimera
