#include "real_worker.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>

#include "chimera/exec/clock.hpp"
#include "chimera/exec/write_watch.hpp"
#include "futex.hpp"
#include "priority_dispatcher.hpp"
#include "real_executive.hpp"
#include "release_policy.hpp"

namespace chimera {

namespace {
// How long a consumer spins for a producer on another CPU before it sleeps (see
// wait_for_predecessors): a few cross-CPU wake-ups' worth on this kind of machine.
constexpr std::int64_t kCatchUpSpinNs = 50'000;

// Release indices are compared modulo 2^32 (the futex word is 32 bits).
bool reached(std::uint32_t completed_plus_one, std::int64_t k) {
  return static_cast<std::int32_t>(completed_plus_one - static_cast<std::uint32_t>(k + 1)) >= 0;
}

void set_own_priority(Worker& w, int priority) noexcept {
  if (w.job.current_priority.load(std::memory_order_relaxed) == priority) return;
  sched_param sp{};
  sp.sched_priority = priority;
  if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0)
    w.job.current_priority.store(priority, std::memory_order_relaxed);  // see PriorityDispatcher::rerank
}
}  // namespace

Worker::~Worker() {
  if (bell_fd >= 0) ::close(bell_fd);
}

void ring_bell(const Worker& w) noexcept {
  if (w.bell_fd < 0) return;
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t put = ::write(w.bell_fd, &one, sizeof(one));  // a full counter still wakes
}

bool Worker::take_mail() {
  const std::uint32_t req = mailbox.request_seq.load(std::memory_order_acquire);  // acquire: see `mail`
  if (req == mailbox.seen) return true;
  mailbox.seen = req;
  return handle(req);
}

void Worker::reply_to(std::uint32_t seq) {
  mailbox.done_seq.store(seq, std::memory_order_release);  // release: publishes `reply`
  detail::futex_wake_all(mailbox.done_seq);
}

bool Worker::handle(std::uint32_t seq) {
  const std::int64_t now = exec->now_ns();
  const TaskState before = task->state();
  const Mail& mail = mailbox.mail;
  switch (mail.kind) {
    case MailKind::kJoin:
      // The control thread has already published `scheduled` for every task of the group.
      schedule.k = mail.at;
      schedule.held = false;
      mailbox.reply = Result<void>{};
      reply_to(seq);
      return true;
    case MailKind::kLeaveAt:
      schedule.leave_at = mail.at;
      schedule.leave_seq = seq;
      // Not released and nothing to finish: an aperiodic task, or one already past its last
      // release before the switch, leaves at once; otherwise after its current job (the loop).
      if (!task->periodic() || task->state() != TaskState::kOn ||
          exec->epoch_ns() + schedule.k * task->period_ns() >= schedule.leave_at)
        leave();
      return true;
    case MailKind::kReinit:
      mailbox.reply = task->reinit(now)
                          ? Result<void>{}
                          : make_error(Errc::kModuleFault, task->name() + ": reinit failed; the task is no longer ON");
      reply_to(seq);
      return task->state() != TaskState::kNotCreated;
    case MailKind::kOnAt:
      // Turned on at its first release, not now: on() publishes its outputs, and a consumer may
      // still be reading the leaving producer's last value of the release before.
      if (task->periodic() && task->state() == TaskState::kOff) {
        schedule.on_at = mail.at;
        schedule.on_seq = seq;
        return true;
      }
      break;
    case MailKind::kSignal:
    case MailKind::kOnHeld: break;
  }
  const Signal request = mail.kind == MailKind::kSignal ? mail.signal : Signal::kOn;
  // A task turning on joins the grid at the next whole multiple of its period. Successors must
  // see that release as scheduled as soon as they can see the task ON, or one of them could run
  // its shared release without waiting for it: publish it before the state changes. (A held
  // task's release is published by the control thread before kJoin.)
  const std::int64_t join = task->periodic() ? release_policy::first_release_index(now, task->period_ns()) : -1;
  const bool turning_on = before != TaskState::kOn && request == Signal::kOn;
  if (turning_on && task->periodic() && mail.kind == MailKind::kSignal)
    precedence->scheduled.store(join, std::memory_order_release);  // release: pairs with successors' acquire load
  mailbox.reply = task->apply(request, now);
  // Given up while stuck in the method: the signal stopped waiting long ago (answering() refuses
  // the task now), and the thread-mates are another thread's. Nothing here is ours to change.
  if (task->given_up()) return false;
  if (before != TaskState::kOn && task->state() == TaskState::kOn) {
    if (task->periodic()) schedule.k = join;
    schedule.held = mail.kind == MailKind::kOnHeld && task->periodic();
    schedule.leave_at = -1;
    on_turned_on();
  }
  const bool alive = task->state() != TaskState::kNotCreated;
  // The thread's count of living tasks; with none left it ends, and says so before answering,
  // so that the control thread knows to join it.
  if (before == TaskState::kNotCreated && alive) ++thread->alive;
  if (before != TaskState::kNotCreated && !alive) --thread->alive;
  if (!alive && thread->alive == 0) thread->exiting.store(true, std::memory_order_release);  // before the answer
  reply_to(seq);
  return alive;
}

void Worker::join_now() {
  const std::uint32_t seq = schedule.on_seq;
  precedence->scheduled.store(schedule.on_at, std::memory_order_release);  // release: successors wait for it
  mailbox.reply = task->apply(Signal::kOn, exec->now_ns());
  if (task->state() == TaskState::kOn) {
    schedule.k = schedule.on_at;
    on_turned_on();
  }
  schedule.on_at = -1;
  schedule.on_seq = 0;
  reply_to(seq);
}

void Worker::leave() {
  const std::uint32_t seq = schedule.leave_seq;
  schedule.leave_at = -1;
  schedule.leave_seq = 0;
  mailbox.last_release_ns = task->state() == TaskState::kOn && task->periodic() && schedule.last_run >= 0
                                ? schedule.last_run * task->period_ns()
                                : kNoRelease;
  mailbox.reply = task->state() == TaskState::kOn ? task->apply(Signal::kOff, exec->now_ns()) : Result<void>{};
  schedule.held = false;
  reply_to(seq);
}

void Worker::on_turned_on() noexcept {
  schedule.last_run = -1;
  task->wake().trigger_var.store(task->trigger_var(), std::memory_order_relaxed);  // producers read it on its own
  task->wake().update_pending.store(false, std::memory_order_relaxed);
  if (task->spec().server) server.turn_on(task->spec().server->budget_ns);
}

void Worker::publish_job(std::int64_t release_abs) {
  const std::int64_t release = release_abs - exec->epoch_ns();
  job.release_ns.store(release, std::memory_order_relaxed);
  job.deadline_ns.store(task->absolute_deadline(release), std::memory_order_relaxed);
  job.active.store(true, std::memory_order_release);  // release: the dispatcher sees the two above
  dispatcher->poke();  // on this CPU the dispatcher preempts us here and sets our priority
}

std::int64_t Worker::run_job(std::int64_t release_abs) {
  const std::int64_t epoch = exec->epoch_ns();
  const std::int64_t start = monotonic_ns();
  task->set_running_deadline(task->absolute_deadline(release_abs - epoch));  // for the overrun watch
  (void)task->begin_job(release_abs - epoch, start - epoch);
  if (task->given_up()) {  // stuck, and given up while it was: nothing more of it is ours
    task->set_running_deadline(TaskShared::kNoJob);
    return 0;
  }
  const std::int64_t used = task->end_job(monotonic_ns() - epoch, -1);
  task->set_running_deadline(TaskShared::kNoJob);
  for (const int v : out_vars)
    if (WriteWatch* watch = exec->watch_of(v); watch != nullptr) watch->written();  // the DDS bridge's exports
  for (Worker* s : subscribers) {
    const int v = s->task->wake().trigger_var.load(std::memory_order_relaxed);  // a hint; the flag below orders
    if (v < 0 || std::find(out_vars.begin(), out_vars.end(), v) == out_vars.end()) continue;
    // acq_rel: our published values happen before the subscriber's cycle that clears the flag
    if (!s->task->wake().update_pending.exchange(true, std::memory_order_acq_rel)) ring_bell(*s);
  }
  if (dispatcher != nullptr) {
    job.active.store(false, std::memory_order_relaxed);               // the dispatcher only ranks; order is not needed
    set_own_priority(*this, PriorityDispatcher::kReleasingPriority);  // wake up able to ask for a rank
  }
  return used;
}

// NOLINTNEXTLINE(readability-make-member-function-const): it publishes the release it is about to run (precedence)
std::int64_t Worker::prepare() {
  if (schedule.on_at >= 0) return exec->epoch_ns() + schedule.on_at * task->period_ns();  // a switch: on then
  if (task->state() != TaskState::kOn) {
    precedence->scheduled.store(-1, std::memory_order_release);  // release: successors stop waiting on us
    return schedule.leave_seq != 0 ? 0 : kNever;                 // failed while a switch's leave waited: answer it now
  }
  if (schedule.held) return kNever;  // waiting for kJoin; `scheduled` is the control thread's until then
  const std::int64_t release_abs = exec->epoch_ns() + schedule.k * task->period_ns();
  if (schedule.leave_seq != 0 && release_abs >= schedule.leave_at) return 0;  // a switch: leave now
  precedence->scheduled.store(schedule.k, std::memory_order_release);         // release: pairs with successors' acquire
  return release_abs;
}

void Worker::act() {
  // A switch's joining task turns on and runs its first release at once: a consumer that shares
  // its thread comes after it in the same pass and must find that release done.
  if (schedule.on_at >= 0) join_now();
  // A task that left ON (a failed cycle: ERROR) between a switch's leave and its commit has left:
  // it answers now, or the switch would wait for a release it no longer runs.
  if (schedule.leave_seq != 0 && task->state() != TaskState::kOn) {
    leave();
    return;
  }
  if (task->state() != TaskState::kOn || schedule.held) return;
  const std::int64_t period = task->period_ns();
  const std::int64_t epoch = exec->epoch_ns();
  if (schedule.leave_seq != 0 && epoch + schedule.k * period >= schedule.leave_at) {
    leave();  // a switch: this task's last release came before the commit
    return;
  }
  const std::int64_t now = monotonic_ns() - epoch;
  const auto late =
      release_policy::late_releases(task->spec().late, schedule.k * period, now, period, task->spec().deadline_ns);
  if (late.skipped != 0) {
    schedule.k += static_cast<std::int64_t>(late.skipped);
    task->skip_releases(late.skipped, now);
    precedence->scheduled.store(schedule.k, std::memory_order_release);  // release: as in prepare()
    // A successor asleep on one of the releases skipped must look again now, not at its bound.
    if (precedence->waiters.load(std::memory_order_seq_cst) != 0)
      detail::futex_wake_all(precedence->completed, futex_scope);
    if (task->state() != TaskState::kOn || now < late.next_release) return;
    if (schedule.leave_seq != 0 && epoch + schedule.k * period >= schedule.leave_at) {
      leave();  // the releases skipped reached the commit: the joining task runs this one
      return;
    }
  }
  const std::int64_t release_abs = epoch + schedule.k * period;
  if (dispatcher != nullptr) publish_job(release_abs);
  wait_for_predecessors(schedule.k, release_abs);
  (void)run_job(release_abs);
  if (task->given_up()) return;  // its thread leaves it, and its thread-mates, alone now
  schedule.last_run = schedule.k;
  // seq_cst store, then seq_cst load of `waiters`: with the successor's seq_cst increment and
  // re-check this is Dekker's pattern, so either it sees our store or we see it waiting.
  precedence->completed.store(static_cast<std::uint32_t>(schedule.k + 1), std::memory_order_seq_cst);
  if (precedence->waiters.load(std::memory_order_seq_cst) != 0)
    detail::futex_wake_all(precedence->completed, futex_scope);
  ++schedule.k;  // under late: run a late cycle runs late; the next release stays on the absolute grid
  // Successors learn at once which release comes next (not at this thread's next pass, which other
  // members may delay): a consumer tells a producer that is behind from one that is not by it.
  if (task->state() == TaskState::kOn && (schedule.leave_seq == 0 || epoch + schedule.k * period < schedule.leave_at))
    precedence->scheduled.store(schedule.k, std::memory_order_release);  // release: as in prepare()
}

void Worker::run_aperiodic() {
  const std::uint32_t req = mailbox.seen;
  const bool served = task->spec().server.has_value();
  const std::int64_t now = monotonic_ns();
  server.refill(now);
  const bool exhausted = served && server.exhausted();
  const int fd = task->trigger().fd;
  std::array<pollfd, 2> fds{pollfd{bell_fd, POLLIN, 0}, pollfd{fd, POLLIN, 0}};
  if (exhausted || !task->wake().update_pending.load(std::memory_order_acquire)) {  // acquire: pairs with the producer
    // An exhausted server waits for its next refill, and does not watch the event source meanwhile.
    const nfds_t n = (fd >= 0 && !exhausted) ? 2 : 1;
    timespec rel{};
    const timespec* timeout = nullptr;
    if (exhausted && server.pending() > 0) {
      rel = to_timespec(std::max<std::int64_t>(0, server.next_refill() - now));
      timeout = &rel;
    }
    (void)::ppoll(fds.data(), n, timeout, nullptr);
    if ((fds[0].revents & POLLIN) != 0) {
      std::uint64_t drained = 0;
      [[maybe_unused]] const ssize_t got = ::read(bell_fd, &drained, sizeof(drained));  // only drains the counter
    }
  }
  if (mailbox.request_seq.load(std::memory_order_acquire) != req) return;  // the mail first; acquire: as in main
  if (exhausted || task->state() != TaskState::kOn) return;
  const bool fd_event = fd >= 0 && (fds[1].revents & (POLLIN | POLLERR | POLLHUP)) != 0;
  const bool update_event =
      task->wake().update_pending.exchange(false, std::memory_order_acq_rel);  // acq_rel: see run_job
  if (!fd_event && !update_event) return;

  const std::int64_t release_abs = monotonic_ns();
  if (dispatcher != nullptr) publish_job(release_abs);
  const std::int64_t start = monotonic_ns();
  const std::int64_t used = run_job(release_abs);
  if (served) server.charge(start, used, task->spec().server->period_ns);
}

void Worker::wait_for_predecessors(std::int64_t release, std::int64_t release_abs) const {
  const std::int64_t give_up =
      release_policy::producer_wait_until(release_abs, monotonic_ns(), task->spec().deadline_ns);
  bool behind = false;  // a producer had an earlier release still to run: not waited for
  // A job spins briefly for a producer on another CPU before it sleeps: the producer, due for the
  // same release, is running it or about to, and a futex sleep and cross-CPU wake-up would cost
  // more than its job (tens of microseconds on a VM, on the chain's path every release).
  const std::int64_t spin_until = monotonic_ns() + kCatchUpSpinNs;
  for (Worker* p : predecessors) {
    for (;;) {
      // acquire: its cycle's outputs are published
      const std::uint32_t done = p->precedence->completed.load(std::memory_order_acquire);
      const bool completed = reached(done, release);
      const bool completed_previous = reached(done, release - 1);
      const std::int64_t joins = p->precedence->joining_k.load(std::memory_order_acquire);  // acquire: the commit's
      const bool joining = joins >= 0 && joins <= release;
      // A joining producer is waited for at its first release as if it were ON already.
      const bool on = joining || p->task->state() == TaskState::kOn;
      // acquire: pairs with its store of the release it is about to run
      const std::int64_t next = joining ? joins : p->precedence->scheduled.load(std::memory_order_acquire);
      if (p->group == group) {
        // A producer on this thread has had its turn in this pass (it comes first in data-flow
        // order); if it has not run the release it is behind, and can only catch up once we
        // return: waiting would be waiting for ourselves, until the bound. Counted like a wait
        // that gave up, since this release runs without its value.
        behind = behind || release_policy::waits_for_producer(on, completed, completed_previous, next, release) ||
                 release_policy::producer_behind(on, completed, completed_previous, next, release);
        break;
      }
      if (!release_policy::waits_for_producer(on, completed, completed_previous, next, release)) {
        behind = behind || release_policy::producer_behind(on, completed, completed_previous, next, release);
        break;
      }
      if (p->cpu != cpu) {
        // Also when catching up: the producer is running the releases just before ours one
        // after another, and a sleep and wake per release would cost more than the job.
        while (!reached(p->precedence->completed.load(std::memory_order_acquire), release) &&  // acquire: as above
               monotonic_ns() < spin_until) {
          detail::cpu_relax();
        }
        if (reached(p->precedence->completed.load(std::memory_order_acquire), release)) continue;  // acquire: as above
      }
      p->precedence->waiters.fetch_add(1, std::memory_order_seq_cst);  // seq_cst: Dekker with the producer (see act)
      const std::uint32_t c = p->precedence->completed.load(std::memory_order_seq_cst);
      bool in_time = true;
      if (!reached(c, release)) in_time = detail::futex_wait(p->precedence->completed, c, give_up, p->futex_scope);
      p->precedence->waiters.fetch_sub(1, std::memory_order_relaxed);  // only a hint for the producer's wake
      if (!in_time && monotonic_ns() >= give_up) {
        task->record_order_timeout();
        return;  // past the bound: run with what the table holds
      }
    }
  }
  if (behind) task->record_order_timeout();  // this release runs without a producer's value of it
}

}  // namespace chimera
