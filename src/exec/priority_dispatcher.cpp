#include "priority_dispatcher.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include "futex.hpp"

namespace chimera {

PriorityDispatcher::PriorityDispatcher(int cpu, SchedulerKind policy, std::vector<Worker*> workers,
                                       const std::vector<TaskUrgency>& urgency)
    : cpu_(cpu),
      policy_(policy),
      workers_(std::move(workers)),
      urgency_{urgency, urgency},
      jobs_(workers_.size()),
      active_(workers_.size(), false),
      order_(workers_.size(), 0),
      priorities_(workers_.size(), 0) {}

PriorityDispatcher::~PriorityDispatcher() {
  if (!started_) return;
  stopping_.store(true, std::memory_order_relaxed);  // read after the bell's acquire below
  bell_.fetch_add(1, std::memory_order_release);     // release: publishes `stopping_`
  detail::futex_wake_all(bell_);
  pthread_join(thread_, nullptr);
}

void PriorityDispatcher::start(bool realtime) {
  realtime_ = realtime;
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<unsigned>(cpu_), &set);
  pthread_attr_setaffinity_np(&attr, sizeof(set), &set);
  if (realtime) {
    sched_param sp{};
    sp.sched_priority = kPriority;
    pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
    pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
    pthread_attr_setschedparam(&attr, &sp);
  }
  auto entry = [](void* self) -> void* {
    static_cast<PriorityDispatcher*>(self)->main();
    return nullptr;
  };
  int rc = pthread_create(&thread_, &attr, entry, this);
  if (rc != 0 && realtime) {  // refused: the executive has already warned once; run it plainly
    pthread_attr_setinheritsched(&attr, PTHREAD_INHERIT_SCHED);
    rc = pthread_create(&thread_, &attr, entry, this);
  }
  pthread_attr_destroy(&attr);
  started_ = rc == 0;
}

void PriorityDispatcher::poke() noexcept {
  bell_.fetch_add(1, std::memory_order_release);  // release: the poker's published job is seen
  detail::futex_wake_all(bell_);
}

void PriorityDispatcher::main() {
  std::uint32_t seen = bell_.load(std::memory_order_acquire);  // acquire: pairs with poke()
  for (;;) {
    if (stopping_.load(std::memory_order_relaxed)) return;  // ordered by the bell's acquire
    rerank();
    const std::uint32_t now = bell_.load(std::memory_order_acquire);  // acquire: pairs with poke()
    if (now == seen) (void)detail::futex_wait(bell_, seen, -1);
    seen = bell_.load(std::memory_order_acquire);  // acquire: pairs with poke()
  }
}

void PriorityDispatcher::rank(SchedulerKind policy, const std::vector<TaskUrgency>& urgency,
                              const std::vector<JobUrgency>& jobs, const std::vector<bool>& active,
                              std::vector<int>& order_scratch, std::vector<int>& priorities) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < urgency.size(); ++i) {
    priorities[i] = 0;
    if (!active[i]) continue;
    if (urgency[i].background) {
      priorities[i] = 1;
      continue;
    }
    order_scratch[n++] = static_cast<int>(i);
  }
  // Insertion sort: a handful of jobs per CPU, and std::sort's worst cases buy nothing here.
  for (std::size_t a = 1; a < n; ++a) {
    const int x = order_scratch[a];
    std::size_t b = a;
    while (b > 0) {
      const auto y = static_cast<std::size_t>(order_scratch[b - 1]);
      const auto xi = static_cast<std::size_t>(x);
      if (!more_urgent(policy, urgency[xi], jobs[xi], urgency[y], jobs[y])) break;
      order_scratch[b] = order_scratch[b - 1];
      --b;
    }
    order_scratch[b] = x;
  }
  for (std::size_t r = 0; r < n; ++r)
    priorities[static_cast<std::size_t>(order_scratch[r])] =
        std::max(kLowestJobPriority, kTopJobPriority - static_cast<int>(r));
}

void PriorityDispatcher::set_urgency(const std::vector<TaskUrgency>& urgency) {
  const std::uint32_t next = flips_.load(std::memory_order_relaxed) + 1;  // only this caller writes it
  urgency_[next % 2] = urgency;                   // the set the dispatcher is not reading: it took the other
  flips_.store(next, std::memory_order_release);  // release: publishes the new set
  poke();
  // The dispatcher takes it at its next ranking; without real-time priorities it may take a
  // while, so wait politely (this is the control thread, never a task's).
  while (started_ && taken_.load(std::memory_order_acquire) != next) {  // acquire: it no longer reads the old set
    poke();
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
  if (!started_) taken_.store(next, std::memory_order_relaxed);
}

void PriorityDispatcher::rerank() {
  const std::uint32_t flips = flips_.load(std::memory_order_acquire);  // acquire: the set it names
  const std::vector<TaskUrgency>& urgency = urgency_[flips % 2];
  for (std::size_t i = 0; i < workers_.size(); ++i) {
    const Worker& w = *workers_[i];
    active_[i] = w.job.active.load(std::memory_order_acquire);  // acquire: its release and deadline
    jobs_[i] =
        JobUrgency{w.job.release_ns.load(std::memory_order_relaxed), w.job.deadline_ns.load(std::memory_order_relaxed)};
  }
  rank(policy_, urgency, jobs_, active_, order_, priorities_);
  taken_.store(flips, std::memory_order_release);  // release: done with the other set
  if (!realtime_) return;
  // Only active jobs are touched: an idle task put itself in the releasing band when its job
  // ended. With real-time priorities the dispatcher and the tasks of its CPU never run at the
  // same time (it preempts them), so the two writers of current_priority never overlap.
  for (std::size_t i = 0; i < workers_.size(); ++i) {
    Worker& w = *workers_[i];
    if (!active_[i] || priorities_[i] == w.job.current_priority.load(std::memory_order_relaxed)) continue;
    sched_param sp{};
    sp.sched_priority = priorities_[i];
    // The acquire load of job.active ordered the worker's own store of `self` before it.
    if (pthread_setschedparam(w.job.self.load(std::memory_order_relaxed), SCHED_FIFO, &sp) == 0)
      w.job.current_priority.store(priorities_[i], std::memory_order_relaxed);
  }
}

}  // namespace chimera
