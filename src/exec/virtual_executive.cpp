#include "virtual_executive.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

namespace chimera {

VirtualExecutive::VirtualExecutive(std::vector<Task*> tasks, const ReleaseOrder& order)
    : tasks_(std::move(tasks)), next_release_(tasks_.size(), -1), dispatch_order_(tasks_.size()) {
  std::iota(dispatch_order_.begin(), dispatch_order_.end(), std::size_t{0});
  // Rate-monotonic priority first (shorter period runs first at a shared instant), then the
  // data-flow rule, then the file: the same order the real executive's priorities and
  // precedence waits produce.
  std::stable_sort(dispatch_order_.begin(), dispatch_order_.end(), [&](std::size_t a, std::size_t b) {
    const auto pa = tasks_[a]->period_ns();
    const auto pb = tasks_[b]->period_ns();
    if (pa != pb) return pa < pb;
    return order.rank[a] < order.rank[b];
  });
}

Result<void> VirtualExecutive::signal(std::size_t task, Signal signal) {
  Task& t = *tasks_[task];
  auto r = t.apply(signal, now_ns_);
  if (t.state() == TaskState::kOn && t.periodic()) {
    if (next_release_[task] < 0) {
      const std::int64_t p = t.period_ns();
      next_release_[task] = (now_ns_ + p - 1) / p * p;  // the first whole multiple of the period from now
    }
  } else {
    next_release_[task] = -1;
  }
  return r;
}

void VirtualExecutive::run_until(std::int64_t end_ns) {
  for (;;) {
    std::int64_t instant = std::numeric_limits<std::int64_t>::max();
    for (std::size_t i = 0; i < tasks_.size(); ++i)
      if (next_release_[i] >= 0) instant = std::min(instant, next_release_[i]);
    if (instant >= end_ns) break;
    now_ns_ = instant;
    for (const std::size_t i : dispatch_order_) {
      if (next_release_[i] != instant) continue;
      Task& t = *tasks_[i];
      t.run_cycle(instant, instant, t.spec().deadline_ns, /*clock_is_virtual=*/true);
      // A task that failed into ERROR stops being released; an ON one is released again.
      next_release_[i] = t.state() == TaskState::kOn ? instant + t.period_ns() : -1;
    }
  }
  now_ns_ = std::max(now_ns_, end_ns);
}

}  // namespace chimera
