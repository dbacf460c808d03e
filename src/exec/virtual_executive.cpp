#include "virtual_executive.hpp"

#include <poll.h>

#include <algorithm>
#include <limits>

#include "chimera/svt/global_table.hpp"
#include "release_policy.hpp"

namespace chimera {

namespace {
constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();
}  // namespace

VirtualExecutive::VirtualExecutive(ExecutiveSetup setup)
    : subsystem_(*setup.subsystem),
      table_(*setup.table),
      tasks_(std::move(setup.tasks)),
      order_(analysis::compute_release_order(subsystem_)),
      plan_(make_schedule_plan(subsystem_, order_, subsystem_cpus(*subsystem_.spec), setup.configuration)),
      cpus_(plan_.cpu),
      slots_(tasks_.size()),
      now_ns_(setup.start_ns) {
  for (Task* t : tasks_) t->set_virtual_clock(true);
  std::vector<int> cpus;
  for (const int c : plan_.cpu)
    if (std::find(cpus.begin(), cpus.end(), c) == cpus.end()) cpus.push_back(c);
  running_.assign(cpus.size(), -1);
  for (const int c : plan_.cpu)
    cpu_slot_.push_back(static_cast<int>(std::find(cpus.begin(), cpus.end(), c) - cpus.begin()));
}

VirtualExecutive::~VirtualExecutive() { shutdown(); }

JobUrgency VirtualExecutive::urgency_of(std::size_t i) const {
  const std::int64_t r = slots_[i].job.release_ns;
  return JobUrgency{r, tasks_[i]->absolute_deadline(r)};
}

bool VirtualExecutive::blocked_by_producer(std::size_t i) const {
  // The same-rate data-flow rule: a job waits for its same-period producers' job of the same
  // release, as the real executive's precedence wait does, and no longer than that wait's bound.
  const Slot& s = slots_[i];
  if (now_ns_ >= s.job.wait_until_ns) return false;
  return std::ranges::any_of(order_.predecessors[i], [&](int p) {
    const Slot& ps = slots_[static_cast<std::size_t>(p)];
    const bool on = tasks_[static_cast<std::size_t>(p)]->state() == TaskState::kOn;
    const bool completed = ps.last_done_release_ns >= s.job.release_ns;
    const bool completed_previous = ps.last_done_release_ns >= s.job.release_ns - tasks_[i]->period_ns();
    const std::int64_t next = ps.job.active ? ps.job.release_ns : ps.next_release_ns;  // what it runs next
    return release_policy::waits_for_producer(on, completed, completed_previous, next, s.job.release_ns);
  });
}

bool VirtualExecutive::starts_without_a_producer(std::size_t i) const {
  // As the real clock counts it: a job that starts while a producer it would wait for has not
  // run its release (the wait's bound passed), or while a producer is behind.
  const Slot& s = slots_[i];
  return std::ranges::any_of(order_.predecessors[i], [&](int p) {
    const Slot& ps = slots_[static_cast<std::size_t>(p)];
    const bool on = tasks_[static_cast<std::size_t>(p)]->state() == TaskState::kOn;
    const bool completed = ps.last_done_release_ns >= s.job.release_ns;
    const bool completed_previous = ps.last_done_release_ns >= s.job.release_ns - tasks_[i]->period_ns();
    const std::int64_t next = ps.job.active ? ps.job.release_ns : ps.next_release_ns;
    return release_policy::waits_for_producer(on, completed, completed_previous, next, s.job.release_ns) ||
           release_policy::producer_behind(on, completed, completed_previous, next, s.job.release_ns);
  });
}

bool VirtualExecutive::ready(std::size_t i) const {
  const Slot& s = slots_[i];
  if (!s.job.active) return false;
  if (s.job.started) return true;
  return !blocked_by_producer(i);
}

void VirtualExecutive::release_periodic(std::size_t i) {
  Task& t = *tasks_[i];
  Slot& s = slots_[i];
  if (s.next_release_ns < 0 || s.job.active || s.next_release_ns > now_ns_) return;
  const std::int64_t period = t.period_ns();
  const auto late =
      release_policy::late_releases(t.spec().late, s.next_release_ns, now_ns_, period, t.spec().deadline_ns);
  if (late.skipped != 0) {
    s.next_release_ns = late.next_release;
    t.skip_releases(late.skipped, now_ns_);
    if (t.state() != TaskState::kOn) {
      s.next_release_ns = -1;
      return;
    }
    if (s.next_release_ns > now_ns_) return;
  }
  const std::int64_t release = s.next_release_ns;
  s.job = Job{true, false, release, 0, 0, release_policy::producer_wait_until(release, now_ns_, t.spec().deadline_ns)};
  s.next_release_ns += period;
}

void VirtualExecutive::drop_if_too_late(std::size_t i) {
  // Under late: skip a release is judged when its job could start, as on the real clock, where
  // the task's thread judges it when it runs again: a job released on time but kept from
  // starting (a stall, a more urgent task) past its deadline is not started; release_periodic
  // then skips it with the others whose deadline has passed.
  const Task& t = *tasks_[i];
  Slot& s = slots_[i];
  if (!s.job.active || s.job.started || t.spec().late != LatePolicy::kSkip || t.spec().deadline_ns <= 0) return;
  if (now_ns_ <= s.job.release_ns + t.spec().deadline_ns) return;
  s.next_release_ns = s.job.release_ns;
  s.job = Job{};
}

void VirtualExecutive::poll_triggers() {
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    Task& t = *tasks_[i];
    Slot& s = slots_[i];
    if (t.periodic() || t.state() != TaskState::kOn) continue;
    if (t.trigger_var() >= 0) {
      const std::uint64_t v = table_.version(static_cast<VarIndex>(t.trigger_var()));
      if (v != s.seen_version) {
        s.seen_version = v;
        ++s.events;  // several writes at one instant are one event: the latest value is what counts
      }
    }
    if (t.trigger().fd >= 0 && s.events == 0 && !s.job.active && now_ns_ >= s.next_fd_poll_ns) {
      pollfd p{t.trigger().fd, POLLIN, 0};
      if (::poll(&p, 1, 0) > 0 && (p.revents & (POLLIN | POLLERR | POLLHUP)) != 0)
        s.events = 1;
      else
        s.next_fd_poll_ns = now_ns_ + kPollPeriodNs;
    }
    const bool background = plan_.urgency[i].background;
    if (s.events > 0 && !s.job.active && (background || !s.server.exhausted())) {
      --s.events;
      s.job = Job{true, false, now_ns_, 0, 0, now_ns_};
    }
  }
}

void VirtualExecutive::refill_servers() {
  for (auto& s : slots_) s.server.refill(now_ns_);
}

void VirtualExecutive::finish(std::size_t i) {
  Task& t = *tasks_[i];
  Slot& s = slots_[i];
  t.end_job(now_ns_, s.job.exec_ns);
  s.last_done_release_ns = s.job.release_ns;
  if (t.spec().server) s.server.charge(s.job_start_ns, s.job.exec_ns, t.spec().server->period_ns);
  s.job = Job{};
  s.next_fd_poll_ns = now_ns_;  // level-triggered: look again right away
  const int c = cpu_slot_[i];
  if (running_[static_cast<std::size_t>(c)] == static_cast<int>(i)) running_[static_cast<std::size_t>(c)] = -1;
  if (t.periodic() && t.state() != TaskState::kOn) s.next_release_ns = -1;
}

void VirtualExecutive::start_job(std::size_t i) {
  Slot& s = slots_[i];
  s.job.started = true;
  s.job_start_ns = now_ns_;
  if (tasks_[i]->periodic() && starts_without_a_producer(i)) tasks_[i]->record_order_timeout();
  const std::int64_t cost = tasks_[i]->begin_job(s.job.release_ns, now_ns_);
  s.job.exec_ns = std::max<std::int64_t>(cost, 0);
  s.job.remaining_ns = tasks_[i]->state() == TaskState::kOn ? s.job.exec_ns : 0;
}

void VirtualExecutive::dispatch() {
  for (;;) {
    // The most urgent ready job of each CPU, and among the CPUs whose choice changes, the most
    // urgent of all first: a job of no simulated time ends at once and may unblock others.
    int pick = -1;
    for (std::size_t c = 0; c < running_.size(); ++c) {
      int best = -1;
      for (std::size_t i = 0; i < tasks_.size(); ++i) {
        if (cpu_slot_[i] != static_cast<int>(c) || !ready(i)) continue;
        if (best < 0 ||
            more_urgent(plan_.policy, plan_.urgency[i], urgency_of(i), plan_.urgency[static_cast<std::size_t>(best)],
                        urgency_of(static_cast<std::size_t>(best))))
          best = static_cast<int>(i);
      }
      if (best < 0 || best == running_[c]) continue;
      const auto b = static_cast<std::size_t>(best);
      if (pick < 0 ||
          more_urgent(plan_.policy, plan_.urgency[b], urgency_of(b), plan_.urgency[static_cast<std::size_t>(pick)],
                      urgency_of(static_cast<std::size_t>(pick))))
        pick = best;
    }
    if (pick < 0) return;
    const auto i = static_cast<std::size_t>(pick);
    Slot& s = slots_[i];
    running_[static_cast<std::size_t>(cpu_slot_[i])] = pick;  // preempts whatever ran there
    if (!s.job.started) start_job(i);
    if (s.job.remaining_ns <= 0) {
      finish(i);
      poll_triggers();  // what it published may wake an aperiodic task at this same instant
    }
  }
}

std::int64_t VirtualExecutive::next_event_after_dispatch() const {
  std::int64_t t = kNever;
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    const Slot& s = slots_[i];
    const Task& task = *tasks_[i];
    // A release already past (late: run catching up after a stall, one job at a time) is due now:
    // never a step back in time.
    if (!s.job.active && s.next_release_ns >= 0) t = std::min(t, std::max(s.next_release_ns, now_ns_));
    if (s.job.active && !s.job.started && s.job.wait_until_ns > now_ns_) t = std::min(t, s.job.wait_until_ns);
    t = std::min(t, s.server.next_refill());
    const bool watching = !task.periodic() && task.state() == TaskState::kOn && task.trigger().fd >= 0;
    if (watching && !s.job.active && s.events == 0) t = std::min(t, std::max(s.next_fd_poll_ns, now_ns_ + 1));
  }
  for (const int r : running_)
    if (r >= 0) t = std::min(t, now_ns_ + slots_[static_cast<std::size_t>(r)].job.remaining_ns);
  return t;
}

void VirtualExecutive::advance_to(std::int64_t t) {
  const std::int64_t dt = t - now_ns_;
  for (const int r : running_)
    if (r >= 0) slots_[static_cast<std::size_t>(r)].job.remaining_ns -= dt;
  now_ns_ = t;
}

void VirtualExecutive::step() {
  stepped_ns_ = now_ns_;
  refill_servers();
  for (const int r : running_)
    if (r >= 0 && slots_[static_cast<std::size_t>(r)].job.remaining_ns <= 0) finish(static_cast<std::size_t>(r));
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    if (!tasks_[i]->periodic()) continue;
    drop_if_too_late(i);
    release_periodic(i);
  }
  poll_triggers();
  dispatch();
}

bool VirtualExecutive::run_until(std::int64_t end_ns, const Doorbell* watch) {
  const std::uint32_t seen = watch != nullptr ? watch->rung() : 0;
  for (;;) {
    step();
    if (watch != nullptr && watch->rung() != seen) return false;
    const std::int64_t t = next_event_after_dispatch();
    if (t >= end_ns) break;
    advance_to(t);
  }
  if (end_ns > now_ns_) advance_to(end_ns);
  return true;
}

void VirtualExecutive::run_for(std::int64_t ns) {
  if (ns <= 0 || stopped_) return;
  const std::int64_t end = now_ns_ + ns;
  // A task that asks for a switch stops the simulation at that instant; the switch happens
  // there, and the run goes on: the same file and inputs give the same trace.
  while (!run_until(end, hooks_.requests))
    if (hooks_.serve_requests) hooks_.serve_requests();
}

Result<void> VirtualExecutive::reinit(std::size_t task) {
  if (tasks_[task]->reinit(now_ns_)) return {};
  return make_error(Errc::kModuleFault, tasks_[task]->name() + ": reinit failed; the task is no longer ON");
}

void VirtualExecutive::end_open_job(std::size_t i) {
  Slot& s = slots_[i];
  if (!s.job.active) return;
  if (s.job.started)
    finish(i);  // a signal is handled between cycles: the job ends now
  else
    s.job = Job{};  // released but not started: it never runs
}

Result<void> VirtualExecutive::signal(std::size_t task, Signal signal) {
  if (stopped_) return make_error(Errc::kState, "the subsystem is stopped");
  Task& t = *tasks_[task];
  Slot& s = slots_[task];
  end_open_job(task);
  auto r = t.apply(signal, now_ns_);
  if (t.state() != TaskState::kOn) {
    s.next_release_ns = -1;
    s.events = 0;
    return r;
  }
  if (t.periodic() && s.next_release_ns < 0) {
    // The first whole multiple of the period from now; if this instant's releases have already
    // run (a switch a task asked for during them), the one after: its producer of this instant
    // has already run it.
    const std::int64_t p = t.period_ns();
    const std::int64_t from = now_ns_ == stepped_ns_ ? now_ns_ + 1 : now_ns_;
    s.next_release_ns = release_policy::first_release_index(from, p) * p;
    s.last_done_release_ns = -1;
  }
  if (!t.periodic()) {
    if (t.trigger_var() >= 0) s.seen_version = table_.version(static_cast<VarIndex>(t.trigger_var()));
    if (t.spec().server) s.server.turn_on(t.spec().server->budget_ns);
    s.next_fd_poll_ns = now_ns_;
  }
  return r;
}

Result<void> VirtualExecutive::turn_on_together(const std::vector<std::size_t>& tasks) {
  for (const std::size_t i : tasks)
    if (auto r = signal(i, Signal::kOn); !r) return r;
  return {};
}

CommitOutcome VirtualExecutive::commit_switch(const SwitchCommit& commit) {
  // Creating tasks takes no simulated time, but a switch that must create them is one that takes
  // longer than a cycle: the old configuration runs on, flag raised, until the next boundary of
  // the fastest task involved.
  const std::int64_t shortest = shortest_period(tasks_, commit);
  if (commit.slow && shortest > 0) (void)run_until(release_policy::next_boundary_after(now_ns_, shortest));
  // Simulated time never runs late: the joining tasks are released from now, the boundary.
  CommitOutcome outcome;
  outcome.joins_from_ns = now_ns_;
  for (const std::size_t i : commit.leaving) (void)signal(i, Signal::kOff);
  for (const std::size_t i : commit.joining)
    if (auto r = signal(i, Signal::kOn); !r && outcome.fault) outcome.fault = r;
  plan_ = make_schedule_plan(subsystem_, order_, subsystem_cpus(*subsystem_.spec), commit.target);
  return outcome;
}

void VirtualExecutive::shutdown() {
  if (stopped_) return;
  // The paper's two-step termination: every task off, then every task killed.
  for (std::size_t i = 0; i < tasks_.size(); ++i)
    if (tasks_[i]->state() == TaskState::kOn) (void)signal(i, Signal::kOff);
  for (std::size_t i = 0; i < tasks_.size(); ++i)
    if (tasks_[i]->state() != TaskState::kNotCreated) (void)signal(i, Signal::kKill);
  stopped_ = true;
}

}  // namespace chimera
