// The stuck-task watch of the main process (docs/processes.md). A thread cannot be killed, so a
// task of the main process stuck in a module method (an endless loop) cannot be stopped as a
// module process's is. What the watch can do, once the task has been inside one method longer
// than StuckBound (cycle(): ten periods or deadlines, at least 200 ms; any other method: 10 s):
//
// - give that method up (Task::give_up): the task is ERROR, holding the illegal-configuration
//   flag, and its thread, should the method ever return, touches neither it nor its thread-mates;
// - move the thread-mates (rm and dm run the tasks of one CPU and period on one thread) to a new
//   thread of the same CPU and priority, which goes on with their releases where the stuck one
//   left them;
// - drop the stuck thread to SCHED_IDLE, so that a spinning method takes only the CPU's idle
//   time, not the CPU from every task below its priority.
//
// A method a signal runs (init, on, off, kill, clear) is given up once that signal has stopped
// waiting for it (its own bound is the same 10 s): the signal holds the control mutex while it
// waits. Signals to the given-up task are refused at once; the stop leaves its thread behind, as
// it does any stuck thread. Runs on the service thread, which takes the control mutex only when
// it gives a task up (and tries again at its next tick while a signal holds it).

#include <pthread.h>
#include <sched.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "futex.hpp"
#include "priority_dispatcher.hpp"
#include "real_executive.hpp"
#include "real_worker.hpp"

namespace chimera {

namespace {
bool drop_to_idle(pthread_t thread) {
  const sched_param idle{};  // SCHED_IDLE takes priority 0
  return pthread_setschedparam(thread, SCHED_IDLE, &idle) == 0;
}
}  // namespace

void RealExecutive::give_up_stuck_methods() {
  const std::int64_t now = now_ns();
  std::unique_lock lock(control_mutex_, std::defer_lock);
  for (std::size_t i = 0; i < workers_.size(); ++i) {
    if (!hosts(i)) continue;  // a module process's task: its supervisor kills the process instead
    Worker& w = *workers_[i];
    const std::optional<Task::Busy> busy = w.task->busy();
    if (!busy || now - busy->since_ns <= StuckBound::of(busy->method, w.task->period_ns(), w.task->spec().deadline_ns))
      continue;
    if (!lock.owns_lock() && !lock.try_lock()) return;  // a signal is under way: the next tick
    if (stopped_at_ns_ >= 0) return;
    // Given up already: its thread, on its way out of the method, may stamp once more.
    if (!w.given_up) give_up(w, *busy, now);
  }
  if (gave_up_any_ && (lock.owns_lock() || lock.try_lock())) keep_given_up_idle();
}

void RealExecutive::give_up(Worker& w, const Task::Busy& busy, std::int64_t now_ns) {
  TaskThread& stuck = *w.thread;
  const double stuck_ms = static_cast<double>(now_ns - busy.since_ns) / 1e6;
  // The thread's count of living members counts this task unless it is stuck in its init.
  const bool counted = w.task->state() != TaskState::kNotCreated;
  std::vector<Worker*> mates;
  for (Worker* m : stuck.members)
    if (m != &w && m->thread == &stuck) mates.push_back(m);
  std::string names;
  for (const Worker* m : mates) names += (names.empty() ? "" : ", ") + m->task->name();
  const std::string reason =
      fmt::format("stuck in {}() for {:.0f} ms; given up: its thread drops to SCHED_IDLE{}", busy_in_name(busy.method),
                  stuck_ms, mates.empty() ? std::string() : fmt::format(", and {} moved to a new thread", names));
  // From here on the stuck thread leaves the task and its mates alone (BusyScope::returned); if
  // the method returned meanwhile, there is nothing to give up.
  if (!w.task->give_up(busy.since_ns, reason.c_str(), now_ns)) return;
  w.given_up = true;
  w.given_up_in = busy.method;
  stuck.given_up = true;
  gave_up_any_ = true;
  // Its jobs are no one's to rank any more (edf, muf), and its successors asleep on its release
  // look again: it is not ON, so they no longer wait for it.
  w.job.active.store(false, std::memory_order_relaxed);  // the dispatcher only ranks; nothing is published with it
  w.precedence->scheduled.store(-1, std::memory_order_release);  // release: as in Worker::prepare()
  detail::futex_wake_all(w.precedence->completed, w.futex_scope);
  if (w.dispatcher != nullptr) w.dispatcher->poke();
  if (stuck.running) (void)drop_to_idle(stuck.handle);
  if (mates.empty()) return;

  threads_.push_back(std::make_unique<TaskThread>());
  TaskThread& next = *threads_.back();
  next.members = mates;
  next.cpu = stuck.cpu;
  next.priority = stuck.priority;
  // The stuck thread's count, less the given-up task; it wrote it before the method began, and the
  // give-up's acquire saw that.
  const int alive = stuck.alive - (counted ? 1 : 0);
  for (Worker* m : mates) m->thread = &next;  // before the new thread starts, under the control mutex
  if (!stuck.running || alive <= 0) return;   // nothing spawned: a spawn starts the new thread
  if (auto started = start_thread(next, alive); !started && events_ != nullptr)
    events_->add(Event{now_ns, w.task->name(), fmt::format("{} stay stopped: {}", names, started.error().message)});
}

// Under the control mutex: `running` and `handle` are the control thread's.
void RealExecutive::keep_given_up_idle() {
  for (const auto& t : threads_) {
    if (!t->given_up || !t->running) continue;
    int policy = 0;
    sched_param param{};
    if (pthread_getschedparam(t->handle, &policy, &param) == 0 && policy != SCHED_IDLE) (void)drop_to_idle(t->handle);
  }
}

}  // namespace chimera
