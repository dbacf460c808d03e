#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstring>

#include "chimera/exec/clock.hpp"
#include "futex.hpp"
#include "real_worker.hpp"
#include "release_policy.hpp"

namespace chimera {

void TaskThread::main() {
  for (Worker* m : members) m->job.self.store(pthread_self(), std::memory_order_relaxed);  // see job.active
  // Touch the stack once so that its pages are resident before the first cycle.
  std::array<char, std::size_t{64} * 1024> prefault;  // NOLINT(cppcoreguidelines-pro-type-member-init): written next
  std::memset(prefault.data(), 0, prefault.size());
  asm volatile("" : : "r"(prefault.data()) : "memory");  // keeps the compiler from dropping the writes

  if (members.size() != 1 || members.front()->task->periodic()) {
    run_periodic_members();
    return;
  }
  // An aperiodic task sleeps in poll() on its event source and its eventfd bell.
  Worker& w = *members.front();
  for (;;) {
    (void)w.take_mail();
    if (w.task->given_up()) return;                       // stuck in a signal's method, and given up
    if (exiting.load(std::memory_order_relaxed)) return;  // its own store, in take_mail()
    if (w.task->state() != TaskState::kOn) {
      pollfd p{w.bell_fd, POLLIN, 0};
      (void)::poll(&p, 1, -1);
      std::uint64_t drained = 0;
      [[maybe_unused]] const ssize_t got = ::read(w.bell_fd, &drained, sizeof(drained));  // only drains the counter
      continue;
    }
    w.run_aperiodic();
    if (w.task->given_up()) return;  // stuck in its cycle and given up: the thread ends with it
  }
}

void TaskThread::run_periodic_members() {
  for (;;) {
    // Read the bell before the mail: a mail posted after this read changes the bell, so the
    // wait below cannot miss it.
    const std::uint32_t rung = bell.load(std::memory_order_acquire);  // acquire: pairs with the poster
    for (Worker* m : members) {
      (void)m->take_mail();
      // Stuck in a signal's method and given up: the other members run on another thread now.
      if (m->task->given_up()) return;
    }
    if (exiting.load(std::memory_order_relaxed)) return;  // its own store, in take_mail()
    std::int64_t earliest = Worker::kNever;
    for (Worker* m : members) earliest = std::min(earliest, m->prepare());
    if (const std::int64_t now = monotonic_ns(); now < earliest) {
      const std::int64_t lead = earliest == Worker::kNever ? 0 : wake_lead();
      if (now < earliest - lead) {
        detail::futex_wait(bell, rung, earliest == Worker::kNever ? -1 : earliest - lead);
        continue;  // mail, a spurious wake, or the wake-up: the loop tells which
      }
      // Woken ahead of the release: spin to it, and to any mail posted meanwhile.
      while (monotonic_ns() < earliest && bell.load(std::memory_order_relaxed) == rung) detail::cpu_relax();
      continue;  // the bell's acquire is at the top of the loop
    }
    // The members' releases that have come, in data-flow order (the members' order), each member
    // caught up before the next: after a stall a producer runs its late releases (late: run) or
    // skips them (late: skip) before its consumers run theirs, so that every consumer finds its
    // producer's value of the same release. A member that does not move on (off, held, left) ends
    // its turn, and so does one that has run kCatchUpPerPass releases: a task whose cycles outlast
    // its period never catches up, and the mail (signals, switches) must still be read.
    // One instant for the whole pass: a release that comes due while the pass runs waits for the
    // next pass for every member alike, or a consumer could run a release its producer, earlier in
    // the pass, had not yet found due.
    constexpr int kCatchUpPerPass = 256;
    const std::int64_t now = monotonic_ns();
    for (Worker* m : members) {
      std::int64_t k = -1;
      for (int n = 0; n < kCatchUpPerPass && m->schedule.k != k && m->prepare() <= now; ++n) {
        k = m->schedule.k;
        m->act();
        // Stuck in its cycle and given up: its thread-mates run on another thread now, and this
        // one ends without touching any of them again.
        if (m->task->given_up()) return;
      }
    }
  }
}

std::int64_t TaskThread::wake_lead() const noexcept {
  for (const Worker* m : members) {
    if (!m->task->periodic() || m->task->state() != TaskState::kOn) continue;
    // Under edf and muf the thread wakes in the releasing band to have its job ranked: a spin
    // there would hold off the ranking of every other job of its CPU.
    if (m->dispatcher != nullptr) return 0;
    const bool waits_on_another_cpu = std::ranges::any_of(
        m->predecessors, [m](const Worker* p) { return p->cpu != m->cpu && p->task->state() == TaskState::kOn; });
    return release_policy::wake_lead(waits_on_another_cpu, m->task->period_ns());
  }
  return 0;
}

}  // namespace chimera
