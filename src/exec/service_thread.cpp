// The real clock's service thread: an ordinary thread of the subsystem interface beside the
// tasks'. It carries out the switches modules ask for (the virtual clock does that inside
// run_for, at the very instant they are asked for), and every kWatchTickNs it watches for jobs
// still running past their deadline.
//
// The overrun watch: end_job counts a missed deadline when the job ends; a job stuck in cycle()
// may never end, and a hard task's error() cannot run on a thread that is still inside cycle().
// So a job more than a tick past its deadline is reported once, and while it is a hard task's it
// holds the illegal-configuration flag, so that the robot interfaces hold still. Once the job
// ends, end_job's own handling follows (error(), then ERROR if it does not recover) and the hold
// goes. A job stuck far longer is given up (stuck_methods.cpp). Not on any task's real-time path.

#include <fmt/format.h>

#include "chimera/exec/clock.hpp"
#include "real_executive.hpp"
#include "real_worker.hpp"

namespace chimera {

void RealExecutive::serve(ServiceHooks hooks) {
  if (service_.joinable()) return;
  service_bell_ = hooks.requests != nullptr ? hooks.requests : &own_bell_;
  service_stop_.store(false, std::memory_order_relaxed);  // before the thread exists
  service_ = std::thread([this, hooks = std::move(hooks)] { service_main(hooks); });
}

void RealExecutive::stop_serving() {
  if (!service_.joinable()) return;
  service_stop_.store(true, std::memory_order_release);  // release: the service sees it after its wake
  service_bell_->ring();
  service_.join();
}

void RealExecutive::service_main(const ServiceHooks& hooks) {
  const Doorbell& bell = *service_bell_;
  std::uint32_t seen = bell.rung();
  if (hooks.serve_requests) hooks.serve_requests();  // anything asked before the thread started
  std::int64_t next_watch = monotonic_ns() + kWatchTickNs;
  for (;;) {
    if (service_stop_.load(std::memory_order_acquire)) return;  // acquire: pairs with stop_serving()
    if (const std::uint32_t now = bell.rung(); now != seen) {
      seen = now;
      if (hooks.serve_requests) hooks.serve_requests();
    }
    if (monotonic_ns() >= next_watch) {
      watch_overruns();
      next_watch += kWatchTickNs;
    }
    (void)bell.wait(seen, next_watch);
  }
}

void RealExecutive::watch_overruns() {
  give_up_stuck_methods();
  const std::int64_t now = now_ns();
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    const std::optional<std::int64_t> deadline = running_deadline(i);
    const bool overdue = deadline && now > *deadline + kWatchTickNs;
    const Task& t = *tasks_[i];
    // A hard task's overdue job holds the flag while it lasts: one hold, raised once, lowered once.
    // A given-up task's ERROR holds the flag now (stuck_methods.cpp).
    const bool hold = overdue && t.hard() && !workers_[i]->given_up;
    if (hold != overdue_hold_[i]) {
      if (hold)
        table_->raise_illegal_configuration();
      else
        table_->lower_illegal_configuration();
      overdue_hold_[i] = hold;
    }
    if (!overdue || overdue_reported_[i] == *deadline) continue;  // this job is reported already
    overdue_reported_[i] = *deadline;
    if (events_ == nullptr) continue;
    const double late_ms = static_cast<double>(now - *deadline) / 1e6;
    const double released_s = static_cast<double>(*deadline - t.spec().deadline_ns) / 1e9;
    events_->add(Event{
        now, t.name(),
        t.hard() ? fmt::format("still running {:.1f} ms past its deadline (released at {:.3f} s): a cycle that does "
                               "not return? The illegal-configuration flag is up until it ends",
                               late_ms, released_s)
                 : fmt::format("still running {:.1f} ms past its deadline (released at {:.3f} s): a cycle that does "
                               "not return? Soft: counted as a miss when it ends",
                               late_ms, released_s)});
  }
}

}  // namespace chimera
