#include "real_executive.hpp"

#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <set>
#include <system_error>
#include <tuple>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "chimera/core/duration_text.hpp"
#include "chimera/core/invariant.hpp"
#include "chimera/exec/clock.hpp"
#include "chimera/exec/write_watch.hpp"
#include "cpu_wake_latency.hpp"
#include "futex.hpp"
#include "priority_dispatcher.hpp"
#include "real_worker.hpp"
#include "release_policy.hpp"

namespace chimera {

namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;
constexpr std::size_t kStackBytes = std::size_t{8} << 20;  // sanitizers need larger frames
#else
constexpr bool kSanitized = false;
constexpr std::size_t kStackBytes = std::size_t{1} << 20;  // locked by mlockall: keep it modest
#endif
// Once the run is ending (begin_stop): how long a signal waits, and how long shutdown() waits for
// a thread that did not answer, before taking it for stuck. The bound on a stop is about twice this.
constexpr std::int64_t kStopReplyTimeoutNs = 1'000'000'000;
constexpr int kTopFixedPriority = 80;
constexpr int kLowestFixedPriority = 2;
constexpr int kBackgroundPriority = 1;
constexpr int kCommitPriority = 85;                // above every fixed priority (80 at most), below the dispatchers
constexpr std::int64_t kCommitMarginNs = 200'000;  // time to post a switch's commit before its boundary

// Runs the calling thread at SCHED_FIFO `priority` while it lives (when real-time priorities are
// wanted and granted), then puts back what it had. Not real-time safe.
class ScopedPriority {
 public:
  ScopedPriority(bool realtime, int priority) {
    if (!realtime || pthread_getschedparam(pthread_self(), &policy_, &param_) != 0) return;
    sched_param sp{};
    sp.sched_priority = priority;
    raised_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
  }
  ~ScopedPriority() {
    if (raised_) pthread_setschedparam(pthread_self(), policy_, &param_);
  }
  ScopedPriority(const ScopedPriority&) = delete;
  ScopedPriority& operator=(const ScopedPriority&) = delete;

 private:
  int policy_ = SCHED_OTHER;
  sched_param param_{};
  bool raised_ = false;
};

void warn_once(std::atomic<bool>& flag, const std::string& message) {
  if (!flag.exchange(true, std::memory_order_relaxed)) spdlog::warn("{}", message);  // a latch only
}
// Once-only warning latches for the whole process.
std::atomic<bool> g_warned_fifo{false};   // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): a latch
std::atomic<bool> g_warned_mlock{false};  // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): a latch

// Fixed priorities (rm, dm): one level per distinct key of the policy, the most urgent at
// kTopFixedPriority. Tasks of one level share it; the same-rate rule orders them by data flow.
std::vector<int> fixed_priorities(const SchedulePlan& plan) {
  const std::size_t n = plan.urgency.size();
  auto key = [&](std::size_t i) {
    const TaskUrgency& u = plan.urgency[i];
    return plan.policy == SchedulerKind::kDm ? std::pair{u.deadline_ns, u.period_ns} : std::pair{u.period_ns, 0L};
  };
  std::set<std::pair<std::int64_t, std::int64_t>> levels;
  for (std::size_t i = 0; i < n; ++i)
    if (!plan.urgency[i].background) levels.insert(key(i));
  std::vector<int> out(n, kBackgroundPriority);
  for (std::size_t i = 0; i < n; ++i) {
    if (plan.urgency[i].background) continue;
    if (!is_fixed_priority(plan.policy)) {
      out[i] = PriorityDispatcher::kReleasingPriority;  // edf / muf: ranked at each release
      continue;
    }
    const auto rank = std::distance(levels.begin(), levels.find(key(i)));
    out[i] = std::max(kLowestFixedPriority, kTopFixedPriority - static_cast<int>(rank));
  }
  return out;
}

}  // namespace

void prepare_realtime_process(bool realtime) {
  if (!realtime) return;
  if (kSanitized) return;  // sanitizers map terabytes of shadow memory: locking it is pointless
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    warn_once(g_warned_mlock, fmt::format("mlockall refused ({}): memory of real-time tasks may be paged",
                                          std::generic_category().message(errno)));
  // Locked, freed heap stays resident (only its top is ever given back). A large temporary (a
  // flight-recorder dump's copy of a ring) gets a mapping of its own, given back when freed:
  // glibc's default threshold rises past the first such block freed, and puts the next in the heap.
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  // Silent when refused: it needs root, as SCHED_FIFO does, whose refusal is already reported.
  (void)detail::hold_cpu_wake_latency();
}

RealExecutive::RealExecutive(ExecutiveSetup setup)
    : subsystem_(*setup.subsystem),
      table_(setup.table),
      events_(setup.events),
      tasks_(std::move(setup.tasks)),
      hosted_(std::move(setup.hosted)),
      order_(analysis::compute_release_order(subsystem_)),
      plan_(make_schedule_plan(subsystem_, order_, subsystem_cpus(*subsystem_.spec), setup.configuration)),
      cpus_(plan_.cpu),
      epoch_ns_(setup.epoch_ns != 0 ? setup.epoch_ns : monotonic_ns() - setup.start_ns),
      realtime_(setup.realtime_priorities) {
  prepare_realtime_process(realtime_);
  watches_ = std::vector<std::atomic<WriteWatch*>>(table_->size());  // value-initialized: none
  for (Task* t : tasks_) {
    t->set_virtual_clock(false);
    if (setup.measure_cpu_time || t->spec().wcet_ns) t->set_exec_clock(Task::ExecClock::kCpu);
  }
  make_workers(plan_, setup.bell_fds);
  link_workers();
  if (!is_fixed_priority(plan_.policy)) make_dispatchers(plan_);
  form_threads();
  overdue_reported_.assign(tasks_.size(), -1);
  overdue_hold_.assign(tasks_.size(), false);
}

void RealExecutive::make_workers(const SchedulePlan& plan, const std::vector<int>& bell_fds) {
  const std::vector<Task*>& tasks = tasks_;
  const std::vector<int> priorities = fixed_priorities(plan);
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    auto w = std::make_unique<Worker>();
    w->exec = this;
    w->task = tasks[i];
    w->index = i;
    w->cpu = plan.cpu[i];
    w->fixed_priority = priorities[i];
    w->precedence = &tasks[i]->precedence();
    // With module processes a successor may sleep on it from another process (link_workers).
    if (!hosted_.empty()) w->futex_scope = detail::FutexScope::kShared;
    if (!tasks[i]->periodic()) {
      w->bell_fd = i < bell_fds.size() && bell_fds[i] >= 0 ? bell_fds[i] : ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
      if (w->bell_fd < 0)
        spdlog::error("{}: no eventfd ({}): the task will not wake for events", tasks[i]->name(),
                      std::generic_category().message(errno));
    }
    for (const auto& b : tasks[i]->resolved().bindings)
      if (b.kind == PortKind::kOutVar)
        if (auto v = table_->find(b.variable)) w->out_vars.push_back(static_cast<int>(*v));
    workers_.push_back(std::move(w));
  }
}

void RealExecutive::link_workers() {
  const analysis::ReleaseOrder& order = order_;
  // Whether aperiodic task `j` reads one of task `i`'s outputs: then `i` may trigger it.
  const auto reads_from = [&](const Worker& j, const Worker& i) {
    return std::ranges::any_of(j.task->resolved().bindings, [&](const PortBinding& b) {
      const auto v = b.kind == PortKind::kInVar ? table_->find(b.variable) : std::nullopt;
      return v && std::ranges::find(i.out_vars, static_cast<int>(*v)) != i.out_vars.end();
    });
  };
  // A task of another process has a Worker here that never runs (docs/processes.md), whose task's
  // precedence, trigger state and bell are the ones its own process uses: in the task block, and
  // an eventfd every process has. So this process's tasks wait for their same-rate producers and
  // wake their aperiodic consumers in any process.
  for (std::size_t i = 0; i < workers_.size(); ++i) {
    for (const int p : order.predecessors[i])
      if (hosts(i)) workers_[i]->predecessors.push_back(workers_[static_cast<std::size_t>(p)].get());
    for (std::size_t j = 0; j < workers_.size(); ++j)
      if (j != i && hosts(i) && !workers_[j]->task->periodic() && reads_from(*workers_[j], *workers_[i]))
        workers_[i]->subscribers.push_back(workers_[j].get());
  }
}

void RealExecutive::make_dispatchers(const SchedulePlan& plan) {
  std::map<int, std::pair<std::vector<Worker*>, std::vector<TaskUrgency>>> per_cpu;
  for (std::size_t i = 0; i < workers_.size(); ++i) {
    if (plan.urgency[i].background) continue;
    per_cpu[plan.cpu[i]].first.push_back(workers_[i].get());
    per_cpu[plan.cpu[i]].second.push_back(plan.urgency[i]);
  }
  for (auto& [cpu, group] : per_cpu) {
    auto d = std::make_unique<PriorityDispatcher>(cpu, plan.policy, group.first, group.second);
    for (Worker* w : group.first) w->dispatcher = d.get();
    d->start(realtime_);
    dispatchers_.push_back(std::move(d));
  }
}

void RealExecutive::form_threads() {
  const analysis::ReleaseOrder& order = order_;
  // Under rm and dm, periodic tasks of one CPU and one period share a priority, and SCHED_FIFO
  // would run their threads one after the other: one thread runs them, in data-flow order.
  // Everything else (aperiodic tasks, edf and muf's per-job priorities) has a thread of its own.
  std::map<std::tuple<int, int, std::int64_t>, TaskThread*> shared;
  std::vector<std::size_t> by_rank(workers_.size());
  for (std::size_t i = 0; i < by_rank.size(); ++i) by_rank[i] = i;
  std::stable_sort(by_rank.begin(), by_rank.end(),
                   [&](std::size_t a, std::size_t b) { return order.rank[a] < order.rank[b]; });
  for (const std::size_t i : by_rank) {
    Worker& w = *workers_[i];
    // A task this process does not run never shares a thread: its state is another process's.
    const bool groups = w.dispatcher == nullptr && w.task->periodic() && hosts(i);
    const auto key = std::tuple{w.cpu, w.fixed_priority, w.task->period_ns()};
    TaskThread* t = groups && shared.contains(key) ? shared[key] : nullptr;
    if (t == nullptr) {
      threads_.push_back(std::make_unique<TaskThread>());
      t = threads_.back().get();
      t->number = static_cast<int>(threads_.size());
      t->cpu = w.cpu;
      t->priority = w.fixed_priority;
      if (groups) shared[key] = t;
    }
    t->members.push_back(&w);
    w.thread = t;
    // The number of the thread it joins, not of the last one made: a thread made between two of
    // its members (another CPU's, another process's task) must not lend the later ones its number.
    w.group = t->number;  // it stays when a watch moves it
  }
}

RealExecutive::~RealExecutive() { shutdown(); }

void RealExecutive::begin_stop() {
  std::lock_guard<std::mutex> lock(control_mutex_);
  reply_timeout_ns_ = std::min(reply_timeout_ns_, kStopReplyTimeoutNs);
}

void RealExecutive::watch_writes(VarIndex v, WriteWatch* watch) {
  watches_[v].store(watch, std::memory_order_release);  // release: the watch is whole before a task sees it
}

std::vector<std::string> RealExecutive::left_behind() const {
  std::vector<std::string> names;
  for (const auto& t : threads_)
    if (t->left_behind)
      for (const Worker* w : t->members)
        if (w->thread == t.get()) names.push_back(w->task->name());  // not those moved off it
  return names;
}

void RealExecutive::shutdown() {
  stop_serving();
  if (stopped_at_ns_ >= 0) return;
  begin_stop();  // however the run ends, it ends within a bound
  // The paper's two-step termination: every task off, then every task killed.
  for (std::size_t i = 0; i < workers_.size(); ++i)
    if (hosts(i) && tasks_[i]->state() == TaskState::kOn) (void)signal(i, Signal::kOff);
  for (std::size_t i = 0; i < workers_.size(); ++i) {
    Worker& w = *workers_[i];
    if (hosts(i) && w.thread->running && w.task->state() != TaskState::kNotCreated) (void)signal(i, Signal::kKill);
  }
  bool any_left = false;
  for (auto& t : threads_) {
    if (!t->running) continue;
    if (!t->unanswered && !t->given_up) {
      pthread_join(t->handle, nullptr);  // its last member's kill ended it
      continue;
    }
    // Stuck in a method (or in a cycle the watch gave up): it gets as long again to come back, then it is left behind.
    // The process ends without it; what it may still touch is kept (left_behind()).
    timespec until{};
    clock_gettime(CLOCK_REALTIME, &until);  // pthread_timedjoin_np's clock
    until.tv_sec += kStopReplyTimeoutNs / 1'000'000'000;
    if (pthread_timedjoin_np(t->handle, nullptr, &until) == 0) {
      t->running = false;
      continue;
    }
    t->left_behind = true;
    any_left = true;
  }
  // The dispatchers read the workers' published jobs: they stop here, with no task thread left
  // to ring them, before the workers can be destroyed (TSAN saw a dispatcher read a freed worker).
  // A thread left behind may still ring its dispatcher: then they stay.
  if (!any_left) {
    for (auto& w : workers_) w->dispatcher = nullptr;
    dispatchers_.clear();
  }
  stopped_at_ns_ = monotonic_ns() - epoch_ns_;
  // A hard job still overdue when the run stopped no longer holds the flag.
  for (std::size_t i = 0; i < overdue_hold_.size(); ++i)
    if (overdue_hold_[i]) table_->lower_illegal_configuration();
  overdue_hold_.assign(overdue_hold_.size(), false);
}

std::int64_t RealExecutive::now_ns() const { return stopped_at_ns_ >= 0 ? stopped_at_ns_ : monotonic_ns() - epoch_ns_; }

void RealExecutive::run_for(std::int64_t ns) {
  if (ns > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(ns));
}

int RealExecutive::fixed_priority(std::size_t index) const { return workers_[index]->fixed_priority; }

int RealExecutive::bell_fd(std::size_t index) const { return workers_[index]->bell_fd; }

std::optional<std::int64_t> RealExecutive::running_deadline(std::size_t index) const noexcept {
  return tasks_[index]->running_deadline();  // a module process's task keeps it in the task block
}

namespace {
void* thread_entry(void* arg) {
  static_cast<TaskThread*>(arg)->main();
  return nullptr;
}
}  // namespace

Result<void> RealExecutive::start_thread(TaskThread& thread, int alive) const {
  TaskThread& w = thread;
  w.exiting.store(false, std::memory_order_relaxed);  // a new thread; the old one was joined
  w.alive = alive;                                    // written before the thread exists
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, kStackBytes);
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  CPU_SET(static_cast<unsigned>(w.cpu), &cpus);
  // Partitioned scheduling needs real-time priorities; ordinary threads do better where the
  // kernel balances them (pinned, they starve behind other load), unless the file pins them.
  const bool file_pins = w.members.front()->task->spec().cpu.has_value();
  if (realtime_ || file_pins) pthread_attr_setaffinity_np(&attr, sizeof(cpu_set_t), &cpus);
  int rc = EPERM;
  if (realtime_) {
    sched_param sp{};
    sp.sched_priority = w.priority;
    pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
    pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
    pthread_attr_setschedparam(&attr, &sp);
    for (Worker* m : w.members) m->job.current_priority.store(w.priority, std::memory_order_relaxed);  // before it runs
    rc = pthread_create(&w.handle, &attr, thread_entry, &w);
    if (rc == EPERM)
      warn_once(g_warned_fifo,
                "SCHED_FIFO is not permitted here: tasks run as ordinary threads, so priorities (and the edf "
                "and muf policies) are not enforced (run as root or grant CAP_SYS_NICE / an rtprio limit)");
  }
  if (rc == EPERM) {
    pthread_attr_setinheritsched(&attr, PTHREAD_INHERIT_SCHED);
    if (!file_pins && sched_getaffinity(0, sizeof(cpu_set_t), &cpus) == 0)
      pthread_attr_setaffinity_np(&attr, sizeof(cpu_set_t), &cpus);  // ordinary threads: unpinned
    rc = pthread_create(&w.handle, &attr, thread_entry, &w);
  }
  pthread_attr_destroy(&attr);
  if (rc != 0)
    return make_error(Errc::kSystem, fmt::format("{}: cannot start its thread: {}", w.members.front()->task->name(),
                                                 std::generic_category().message(rc)));
  w.running = true;
  return {};
}

std::uint32_t RealExecutive::send(Worker& w, const Mail& mail) {
  w.mailbox.mail = mail;
  const std::uint32_t seq = w.mailbox.request_seq.load(std::memory_order_relaxed) + 1;  // only this thread writes it
  w.mailbox.request_seq.store(seq, std::memory_order_release);                          // release: publishes `mail`
  detail::futex_wake_all(w.mailbox.request_seq);
  // The thread sleeps on its bell whatever it waits for (an aperiodic task on its eventfd).
  w.thread->bell.fetch_add(1, std::memory_order_release);  // release: the mail is seen after the wake
  detail::futex_wake_all(w.thread->bell);
  ring_bell(w);
  return seq;
}

Result<void> RealExecutive::await(Worker& w, std::uint32_t seq) const {
  const std::int64_t give_up = monotonic_ns() + reply_timeout_ns_;
  for (;;) {
    const std::uint32_t done = w.mailbox.done_seq.load(std::memory_order_acquire);  // acquire: see `reply`
    if (done == seq) break;
    if (!detail::futex_wait(w.mailbox.done_seq, done, give_up) && monotonic_ns() >= give_up) {
      w.thread->unanswered = true;
      return make_error(Errc::kModuleFault, fmt::format("{}: no answer within {} (a method is stuck?)", w.task->name(),
                                                        format_duration(reply_timeout_ns_)));
    }
  }
  Result<void> r = std::move(w.mailbox.reply);
  w.mailbox.reply = Result<void>{};
  if (w.thread->exiting.load(std::memory_order_acquire)) {  // acquire: set before the answer
    pthread_join(w.thread->handle, nullptr);                // its last member was killed (or failed its init)
    w.thread->running = false;
  }
  return r;
}

Result<void> RealExecutive::answering(Worker& w) {
  if (w.given_up)
    return make_error(Errc::kState,
                      fmt::format("{}: stuck in {}(), and given up: a task of the main process cannot be "
                                  "stopped or restarted; run a module you do not trust in a module process (process:)",
                                  w.task->name(), busy_in_name(w.given_up_in)));
  TaskThread& t = *w.thread;
  if (!t.unanswered) return {};
  // Caught up: every member's last mail answered (acquire: what it did before answering is seen).
  const bool caught_up = std::all_of(t.members.begin(), t.members.end(), [](const Worker* m) {
    return m->mailbox.done_seq.load(std::memory_order_acquire) ==
           m->mailbox.request_seq.load(std::memory_order_relaxed);  // relaxed: only this thread writes it
  });
  if (caught_up) {
    t.unanswered = false;
    return {};
  }
  return make_error(
      Errc::kModuleFault,
      fmt::format("{}: its thread has not answered since an earlier signal (a method is stuck?)", w.task->name()));
}

Result<void> RealExecutive::post(Worker& w, Mail mail) {
  if (auto ok = answering(w); !ok) return ok;
  return await(w, send(w, mail));
}

Result<void> RealExecutive::post_all(const std::vector<std::size_t>& indices, const std::vector<Mail>& mails) {
  std::vector<std::uint32_t> seqs;
  seqs.reserve(indices.size());
  std::vector<bool> sent;
  Result<void> first;
  for (std::size_t n = 0; n < indices.size(); ++n) {
    auto ok = answering(*workers_[indices[n]]);
    if (!ok && first) first = ok;
    sent.push_back(ok.ok());
    seqs.push_back(ok ? send(*workers_[indices[n]], mails[n]) : 0);
  }
  for (std::size_t n = 0; n < indices.size(); ++n)
    if (sent[n])
      if (auto r = await(*workers_[indices[n]], seqs[n]); !r && first) first = r;
  return first;
}

Result<void> RealExecutive::signal(std::size_t index, Signal sig) {
  std::lock_guard<std::mutex> lock(control_mutex_);
  if (stopped_at_ns_ >= 0) return make_error(Errc::kState, "the subsystem is stopped");
  CHIMERA_INVARIANT(hosts(index), "RealExecutive::signal() to a task another process runs");
  Worker& w = *workers_[index];
  if (!w.thread->running) {
    if (sig != Signal::kSpawn) return w.task->apply(sig, now_ns());  // refused by the state table
    if (auto started = start_thread(*w.thread); !started) return started;
  }
  return post(w, Mail{MailKind::kSignal, sig, 0});
}

Result<void> RealExecutive::turn_on_together(const std::vector<std::size_t>& indices) {
  std::lock_guard<std::mutex> lock(control_mutex_);
  // All at once, then every answer: one at a time, 1,000 tasks took tens of milliseconds here.
  // Above the tasks' priorities, as a switch's commit: the joins are timed to a release, and a
  // control thread preempted by the tasks it wakes (or by anything else) would post them late.
  const ScopedPriority urgent(realtime_, kCommitPriority);
  const std::int64_t held_from = monotonic_ns();
  if (auto r = post_all(indices, std::vector<Mail>(indices.size(), Mail{MailKind::kOnHeld, Signal::kOn, 0})); !r)
    return r;
  // Every task is on and waits; now one instant for all: each task's first release is its first
  // grid point at or after it, published before any is let go (the same-rate rule reads it). The
  // instant leaves time to post the joins (as long again as posting the holds took): a task let
  // go after its first release would start late, and a hard one would miss its first deadline.
  const std::int64_t instant = now_ns() + (monotonic_ns() - held_from) + kCommitMarginNs;
  std::vector<std::size_t> joining;
  std::vector<Mail> joins;
  for (const std::size_t i : indices) {
    Worker& w = *workers_[i];
    if (!w.task->periodic() || w.task->state() != TaskState::kOn) continue;
    const std::int64_t k = release_policy::first_release_index(instant, w.task->period_ns());
    w.precedence->scheduled.store(k, std::memory_order_release);  // release: pairs with successors' acquire load
    joining.push_back(i);
    joins.push_back(Mail{MailKind::kJoin, Signal::kOn, k});
  }
  return post_all(joining, joins);
}

std::int64_t RealExecutive::next_commit_ns(const SwitchCommit& commit) const {
  // At the next boundary of the fastest task involved that leaves time to post the commit.
  const std::int64_t shortest = shortest_period(tasks_, commit);
  const std::int64_t now = now_ns();
  return shortest > 0 ? release_policy::next_boundary_after(now + kCommitMarginNs, shortest) : now;
}

CommitOutcome RealExecutive::commit_switch(const SwitchCommit& commit) {
  const std::vector<std::size_t>& leaving = commit.leaving;
  const std::vector<std::size_t>& joining = commit.joining;
  const bool leave_part = commit.part != SwitchCommit::Part::kJoin;
  const bool join_part = commit.part != SwitchCommit::Part::kLeave;
  CommitOutcome outcome;
  {
    std::lock_guard<std::mutex> lock(control_mutex_);
    const std::int64_t commit_ns = commit.at_ns >= 0 ? commit.at_ns : next_commit_ns(commit);
    // Every leaving task answers once it is off: after its last release before the commit. Only
    // then may a joining task turn on, since on() publishes outputs a leaving task wrote: one
    // writer per variable at any time.
    // Successors of the joining tasks must wait for them from the commit's release on, even if
    // the commit runs late: tell them before anything changes.
    if (leave_part) publish_joins(joining, commit_ns);
    // The commit is timed to a cycle boundary: the control thread runs it at a real-time priority
    // above the tasks', so that it is not the one that comes late.
    const ScopedPriority urgent(realtime_, kCommitPriority);
    outcome.joins_from_ns = commit_ns;
    if (leave_part) {
      const std::vector<Mail> leave(leaving.size(), Mail{MailKind::kLeaveAt, Signal::kOff, epoch_ns_ + commit_ns});
      outcome.fault = post_all(leaving, leave);
      // Posted late (the control thread held up past the commit's instant), a leave finds its task
      // has run the commit's release, or more: the joining tasks start after the last of those.
      for (const std::size_t i : leaving) {
        const std::int64_t last = workers_[i]->mailbox.last_release_ns;  // published by the answer
        if (last != Worker::kNoRelease) outcome.joins_from_ns = std::max(outcome.joins_from_ns, last + 1);
      }
    }
    if (join_part) {
      // Each joining task turns on right before its first release from the commit on, on its own
      // thread: not earlier, since on() publishes outputs a consumer may still be reading the
      // leaving producer's last value of. Its first release is the commit's even if the commit ran
      // late (then it runs late) unless a leaving task ran that one: no release may go unproduced,
      // nor be produced twice. They are all posted at once and answer as each turns on.
      if (outcome.joins_from_ns != commit_ns || !leave_part) publish_joins(joining, outcome.joins_from_ns);
      std::vector<Mail> join;
      for (const std::size_t i : joining) {
        const Worker& w = *workers_[i];
        const std::int64_t p = w.task->periodic() ? w.task->period_ns() : 1;
        join.push_back(
            Mail{MailKind::kOnAt, Signal::kOn, release_policy::first_release_index(outcome.joins_from_ns, p)});
      }
      if (auto on = post_all(joining, join); outcome.fault && !on) outcome.fault = on;
      for (const std::size_t i : joining)
        workers_[i]->precedence->joining_k.store(-1, std::memory_order_release);  // scheduled says it now
    }
  }
  if (join_part) set_plan(make_schedule_plan(subsystem_, order_, subsystem_cpus(*subsystem_.spec), commit.target));
  return outcome;
}

void RealExecutive::publish_joins(const std::vector<std::size_t>& joining, std::int64_t from_ns) {
  for (const std::size_t i : joining) {
    Worker& w = *workers_[i];
    if (!w.task->periodic()) continue;
    w.precedence->joining_k.store(release_policy::first_release_index(from_ns, w.task->period_ns()),
                                  std::memory_order_release);  // release: pairs with successors' acquire
    // A successor asleep on it for a release it no longer joins at must look again, not sleep to
    // its bound: the leaving producer ran that release. (One just going to sleep may still sleep
    // to its bound: a bounded wait, and only when a commit was posted late.)
    if (w.precedence->waiters.load(std::memory_order_seq_cst) != 0)  // seq_cst: as in Worker::act
      detail::futex_wake_all(w.precedence->completed, w.futex_scope);
  }
}

void RealExecutive::set_plan(SchedulePlan plan) {
  std::lock_guard<std::mutex> lock(control_mutex_);
  // Fixed priorities depend on periods and deadlines only and stay; the CPUs stay (the plan
  // places every task of the file, whatever configuration is on).
  for (auto& d : dispatchers_) {
    std::vector<TaskUrgency> urgency;
    for (const Worker* w : d->workers()) urgency.push_back(plan.urgency[w->index]);
    d->set_urgency(urgency);
  }
  plan_ = std::move(plan);
}

Result<void> RealExecutive::reinit(std::size_t index) {
  std::lock_guard<std::mutex> lock(control_mutex_);
  return post(*workers_[index], Mail{MailKind::kReinit, Signal::kOn, 0});
}

void RealExecutive::variable_written(VarIndex v) {
  for (auto& w : workers_) {
    TaskWake& wake = w->task->wake();
    if (wake.trigger_var.load(std::memory_order_relaxed) != static_cast<int>(v)) continue;  // a hint, see below
    // acq_rel: the value written happens before the cycle that clears the flag
    if (!wake.update_pending.exchange(true, std::memory_order_acq_rel)) ring_bell(*w);
  }
}

}  // namespace chimera
