#include "real_executive.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <set>
#include <system_error>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "chimera/exec/clock.hpp"
#include "futex.hpp"

namespace chimera {

namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;
constexpr std::size_t kStackBytes = std::size_t{8} << 20;  // sanitizers need larger frames
#else
constexpr bool kSanitized = false;
constexpr std::size_t kStackBytes = std::size_t{1} << 20;  // locked by mlockall: keep it modest
#endif
constexpr std::int64_t kReplyTimeoutNs = 10'000'000'000;

void warn_once(std::atomic<bool>& flag, const std::string& message) {
  if (!flag.exchange(true, std::memory_order_relaxed)) spdlog::warn("{}", message);  // a latch only
}
// Once-only warning latches for the whole process.
std::atomic<bool> g_warned_fifo{false};   // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): a latch
std::atomic<bool> g_warned_mlock{false};  // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): a latch

// Release indices are compared modulo 2^32 (the futex word is 32 bits).
bool reached(std::uint32_t completed_plus_one, std::int64_t k) {
  return static_cast<std::int32_t>(completed_plus_one - static_cast<std::uint32_t>(k + 1)) >= 0;
}

}  // namespace

void prepare_realtime_process(bool realtime) {
  if (!realtime) return;
  if (kSanitized) return;  // sanitizers map terabytes of shadow memory: locking it is pointless
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    warn_once(g_warned_mlock, fmt::format("mlockall refused ({}): memory of real-time tasks may be paged",
                                          std::generic_category().message(errno)));
}

struct RealExecutive::Worker {
  RealExecutive* exec = nullptr;
  Task* task = nullptr;
  std::vector<Worker*> predecessors;
  int priority = 1;
  cpu_set_t cpus{};
  bool pinned = false;
  pthread_t thread{};
  bool running = false;

  // Mailbox: written by the control thread, read by the task's thread.
  alignas(64) std::atomic<std::uint32_t> request_seq{0};
  Signal request = Signal::kSpawn;
  // Reply: written by the task's thread, read by the control thread.
  alignas(64) std::atomic<std::uint32_t> done_seq{0};
  Result<void> reply;
  // Precedence: the last release completed (+1, modulo 2^32), and how many successors sleep on it.
  alignas(64) std::atomic<std::uint32_t> completed{0};
  std::atomic<std::uint32_t> waiters{0};
  std::atomic<std::int64_t> scheduled{-1};  // release index about to run; -1 when not released

  void main();
  bool handle(std::uint32_t seq, std::int64_t& k);
  void wait_for_predecessors(std::int64_t k, std::int64_t release_abs) const;
};

void RealExecutive::Worker::main() {
  // Touch the stack once so that its pages are resident before the first cycle.
  std::array<char, std::size_t{64} * 1024> prefault;  // NOLINT(cppcoreguidelines-pro-type-member-init): written next
  std::memset(prefault.data(), 0, prefault.size());
  asm volatile("" : : "r"(prefault.data()) : "memory");  // keeps the compiler from dropping the writes

  std::uint32_t seen = 0;
  std::int64_t k = 0;
  const std::int64_t period = task->period_ns();
  for (;;) {
    const std::uint32_t req = request_seq.load(std::memory_order_acquire);  // acquire: see `request`
    if (req != seen) {
      seen = req;
      if (!handle(req, k)) return;
      continue;
    }
    if (task->state() != TaskState::kOn || !task->periodic()) {
      scheduled.store(-1, std::memory_order_release);  // release: successors stop waiting on us
      detail::futex_wait(request_seq, req, -1);
      continue;
    }
    const std::int64_t release_abs = exec->epoch_ns_ + k * period;
    scheduled.store(k, std::memory_order_release);  // release: pairs with successors' acquire load
    if (monotonic_ns() < release_abs) {
      detail::futex_wait(request_seq, req, release_abs);
      continue;  // a signal, a spurious wake, or the release: the loop tells which
    }
    wait_for_predecessors(k, release_abs);
    const std::int64_t start = monotonic_ns();
    task->run_cycle(release_abs - exec->epoch_ns_, start - exec->epoch_ns_, task->spec().deadline_ns, false);
    // seq_cst store, then seq_cst load of `waiters`: with the successor's seq_cst increment and
    // re-check this is Dekker's pattern, so either it sees our store or we see it waiting.
    completed.store(static_cast<std::uint32_t>(k + 1), std::memory_order_seq_cst);
    if (waiters.load(std::memory_order_seq_cst) != 0) detail::futex_wake_all(completed);
    ++k;  // a late cycle runs late; the next release stays on the absolute grid
  }
}

bool RealExecutive::Worker::handle(std::uint32_t seq, std::int64_t& k) {
  const std::int64_t now = exec->now_ns();
  const TaskState before = task->state();
  reply = task->apply(request, now);
  if (before != TaskState::kOn && task->state() == TaskState::kOn && task->periodic()) {
    const std::int64_t p = task->period_ns();
    k = (now + p - 1) / p;  // join the grid at the next whole multiple of the period
  }
  const bool alive = task->state() != TaskState::kNotCreated;
  done_seq.store(seq, std::memory_order_release);  // release: publishes `reply`
  detail::futex_wake_all(done_seq);
  return alive;
}

void RealExecutive::Worker::wait_for_predecessors(std::int64_t k, std::int64_t release_abs) const {
  // Bounded: a predecessor that keeps us waiting more than half our deadline no longer holds us
  // back. Counted from when the wait starts, so that the order still holds while tasks catch up
  // after a stall (when every release is already in the past).
  const std::int64_t give_up = std::max(release_abs, monotonic_ns()) + task->spec().deadline_ns / 2;
  for (Worker* p : predecessors) {
    for (;;) {
      if (reached(p->completed.load(std::memory_order_acquire), k)) break;  // acquire: its cycle is done
      if (p->task->state() != TaskState::kOn) break;
      const std::int64_t s = p->scheduled.load(std::memory_order_acquire);  // acquire: pairs with its store
      if (s < 0 || s > k) break;                           // not released, or joined after this instant
      p->waiters.fetch_add(1, std::memory_order_seq_cst);  // seq_cst: Dekker with the producer (see main)
      const std::uint32_t c = p->completed.load(std::memory_order_seq_cst);
      bool in_time = true;
      if (!reached(c, k)) in_time = detail::futex_wait(p->completed, c, give_up);
      p->waiters.fetch_sub(1, std::memory_order_relaxed);  // only a hint for the producer's wake
      if (!in_time && monotonic_ns() >= give_up) {
        task->record_order_timeout();
        return;  // past the bound: run with what the table holds
      }
    }
  }
}

RealExecutive::RealExecutive(const std::vector<Task*>& tasks, const ReleaseOrder& order, const SubsystemSpec& spec,
                             bool realtime)
    : epoch_ns_(monotonic_ns()), realtime_(realtime) {
  // SCHED_FIFO priorities by rate: the shortest period gets the highest priority.
  std::set<std::int64_t> periods;
  for (Task* t : tasks)
    if (t->periodic()) periods.insert(t->period_ns());
  const long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
  for (Task* t : tasks) {
    auto w = std::make_unique<Worker>();
    w->exec = this;
    w->task = t;
    const auto rank = t->periodic() ? std::distance(periods.begin(), periods.find(t->period_ns()))
                                    : static_cast<long>(periods.size());
    w->priority = std::max(1, 80 - static_cast<int>(rank));
    CPU_ZERO(&w->cpus);
    if (t->spec().cpu) {
      CPU_SET(static_cast<unsigned>(*t->spec().cpu), &w->cpus);
      w->pinned = true;
    } else if (!spec.cpus.empty()) {
      for (const int c : spec.cpus)
        if (c < ncpu) CPU_SET(static_cast<unsigned>(c), &w->cpus);
      w->pinned = true;
    }
    workers_.push_back(std::move(w));
  }
  for (std::size_t i = 0; i < workers_.size(); ++i)
    for (const int p : order.predecessors[i])
      workers_[i]->predecessors.push_back(workers_[static_cast<std::size_t>(p)].get());
}

RealExecutive::~RealExecutive() {
  for (auto& w : workers_) {
    if (w->running && w->task->state() != TaskState::kNotCreated)
      (void)signal(static_cast<std::size_t>(&w - workers_.data()), Signal::kKill);
    if (w->running) pthread_join(w->thread, nullptr);
  }
}

std::int64_t RealExecutive::now_ns() const { return monotonic_ns() - epoch_ns_; }

namespace {
void* worker_entry(void* arg) {
  static_cast<RealExecutive::Worker*>(arg)->main();
  return nullptr;
}
}  // namespace

Result<void> RealExecutive::signal(std::size_t index, Signal sig) {
  std::lock_guard<std::mutex> lock(control_mutex_);
  Worker& w = *workers_[index];
  if (!w.running) {
    if (sig != Signal::kSpawn) return w.task->apply(sig, now_ns());  // refused by the state table
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setstacksize(&attr, kStackBytes);
    if (w.pinned) pthread_attr_setaffinity_np(&attr, sizeof(cpu_set_t), &w.cpus);
    int rc = EPERM;
    if (realtime_) {
      sched_param sp{};
      sp.sched_priority = w.priority;
      pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
      pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
      pthread_attr_setschedparam(&attr, &sp);
      rc = pthread_create(&w.thread, &attr, worker_entry, &w);
      if (rc == EPERM)
        warn_once(g_warned_fifo,
                  "SCHED_FIFO is not permitted here: tasks run as ordinary threads "
                  "(run as root or grant CAP_SYS_NICE / an rtprio limit for real-time priorities)");
    }
    if (rc == EPERM) {
      pthread_attr_setinheritsched(&attr, PTHREAD_INHERIT_SCHED);
      rc = pthread_create(&w.thread, &attr, worker_entry, &w);
    }
    pthread_attr_destroy(&attr);
    if (rc != 0)
      return make_error(Errc::kSystem, fmt::format("{}: cannot start its thread: {}", w.task->name(),
                                                   std::generic_category().message(rc)));
    w.running = true;
  }
  w.request = sig;
  const std::uint32_t seq = w.request_seq.load(std::memory_order_relaxed) + 1;  // only this thread writes it
  w.request_seq.store(seq, std::memory_order_release);                          // release: publishes `request`
  detail::futex_wake_all(w.request_seq);
  const std::int64_t give_up = monotonic_ns() + kReplyTimeoutNs;
  for (;;) {
    const std::uint32_t done = w.done_seq.load(std::memory_order_acquire);  // acquire: see `reply`
    if (done == seq) break;
    if (!detail::futex_wait(w.done_seq, done, give_up) && monotonic_ns() >= give_up)
      return make_error(Errc::kModuleFault, fmt::format("{}: no answer to {} within 10 s (a method is stuck?)",
                                                        w.task->name(), signal_name(sig)));
  }
  Result<void> r = std::move(w.reply);
  w.reply = Result<void>{};
  if (w.task->state() == TaskState::kNotCreated) {
    pthread_join(w.thread, nullptr);  // its thread has returned after the kill (or a failed init)
    w.running = false;
  }
  return r;
}

}  // namespace chimera
