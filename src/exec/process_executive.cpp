#include "process_executive.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/eventfd.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <map>
#include <mutex>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "event_log.hpp"

namespace chimera {

namespace {

// The state letter of /proc/PID/stat ('R', 'S', 'T' stopped, 't' traced, 'Z'...), or 0 if it
// cannot be read (the process is gone). The name in parentheses may hold anything, ')' too.
char process_state(pid_t pid) {
  std::array<char, 512> buffer{};
  const std::string path = fmt::format("/proc/{}/stat", pid);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);  // NOLINT(*-vararg)
  if (fd < 0) return 0;
  const ssize_t n = ::read(fd, buffer.data(), buffer.size() - 1);
  ::close(fd);
  if (n <= 0) return 0;
  const std::string_view text(buffer.data(), static_cast<std::size_t>(n));
  const auto name_end = text.rfind(')');
  if (name_end == std::string_view::npos || name_end + 2 >= text.size()) return 0;
  return text[name_end + 2];
}

ProcessCommand command_for(ProcessCommandKind kind, std::size_t task, Signal signal = Signal::kSpawn) {
  ProcessCommand c;
  c.kind = kind;
  c.signal = signal;
  c.count = 1;
  c.tasks[0] = static_cast<std::uint32_t>(task);
  return c;
}

}  // namespace

ProcessExecutive::ProcessExecutive(ExecutiveSetup setup)
    : tasks_(setup.tasks),
      events_(setup.events),
      realtime_(setup.realtime_priorities),
      block_(setup.processes.block),
      launch_{setup.processes.worker_program,
              setup.processes.worker_args,
              setup.processes.block->fd(),
              setup.processes.history_fd,
              {}} {
  // One ModuleProcess per process name other than main, in order of first appearance.
  std::map<std::string, int> index;
  std::vector<bool> hosted(tasks_.size(), true);
  std::vector<std::vector<std::size_t>> members;
  std::vector<std::string> names;
  owner_.assign(tasks_.size(), -1);
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    const std::string& name = tasks_[i]->spec().process;
    if (name == kMainProcess) continue;
    auto [it, added] = index.emplace(name, static_cast<int>(names.size()));
    if (added) {
      names.push_back(name);
      members.emplace_back();
    }
    owner_[i] = it->second;
    members[static_cast<std::size_t>(it->second)].push_back(i);
    hosted[i] = false;
  }
  for (std::size_t k = 0; k < names.size(); ++k)
    processes_.push_back(std::make_unique<ModuleProcess>(names[k], members[k], k));
  setup.hosted = std::move(hosted);
  local_ = std::make_unique<RealExecutive>(std::move(setup));
  // Before any worker starts: they take this epoch, so that every release is on one grid.
  block_->set_epoch_ns(local_->epoch_ns());
  // And every aperiodic task's bell, so that its producers in any process can wake it.
  for (std::size_t i = 0; i < tasks_.size(); ++i)
    if (const int fd = local_->bell_fd(i); fd >= 0) launch_.bells.emplace_back(i, fd);
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) spdlog::error("no eventfd for the process supervisor: a module process's end is seen late");
  supervisor_ = std::thread([this] { supervise(); });
}

ProcessExecutive::~ProcessExecutive() {
  shutdown();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

ModuleProcess* ProcessExecutive::owner(std::size_t task) const {
  const int k = owner_[task];
  return k < 0 ? nullptr : processes_[static_cast<std::size_t>(k)].get();
}

Result<void> ProcessExecutive::signal(std::size_t task, Signal signal) {
  ModuleProcess* p = owner(task);
  if (p == nullptr) return local_->signal(task, signal);
  if (stopped_) return make_error(Errc::kState, "the subsystem is stopped");
  std::lock_guard<std::mutex> lock(p->mutex);
  if (p->end_marked) handle_end(*p);  // seen dead by its life lock: reaped now, so clear can start it again
  if (!p->running()) {
    if (!p->ended.empty()) {
      // Its process has ended: clear starts it again; kill destroys the task without one.
      if (signal == Signal::kClear && tasks_[task]->state() == TaskState::kError) return restart(*p, task);
      if (signal == Signal::kKill) {
        (void)tasks_[task]->forget_lost_process();
        return {};
      }
      return make_error(Errc::kState, fmt::format("{}: its process {} has ended ({}); clear starts it again",
                                                  tasks_[task]->name(), p->name(), p->ended));
    }
    if (signal != Signal::kSpawn) return tasks_[task]->apply(signal, now_ns());  // refused: NOT CREATED
    if (auto started = start(*p); !started) return started;
  }
  return send(*p, command_for(ProcessCommandKind::kSignal, task, signal));
}

Result<void> ProcessExecutive::start(ModuleProcess& p) {
  auto started = p.start(launch_);
  wake_supervisor();  // a new pidfd to watch
  if (started) {
    // Ready means it holds its life lock: the watcher may wait on it now.
    std::lock_guard<std::mutex> lock(watchers_mutex_);
    watchers_.emplace_back([this, &p, generation = p.generation(), pid = p.pid()] { watch_life(p, generation, pid); });
  }
  return started;
}

Result<void> ProcessExecutive::send(ModuleProcess& p, const ProcessCommand& command) {
  if (p.end_marked) {
    handle_end(p);  // dead already: reaped now, and the command refused as to any ended process
    return make_error(Errc::kSystem, fmt::format("process {} has ended ({})", p.name(), p.ended));
  }
  auto r = p.command(command);
  if (p.death_seen()) handle_end(p);
  return r;
}

void ProcessExecutive::mark_end(ModuleProcess& p, const std::string& how) {
  const std::string killed_for = p.kill_reason();
  p.ended = killed_for.empty() ? how : fmt::format("killed by the supervisor: {}", killed_for);
  const std::string reason = fmt::format("its process {} died ({})", p.name(), p.ended);
  const std::int64_t now = now_ns();
  for (const std::size_t i : p.tasks()) tasks_[i]->lose_process(reason.c_str(), now);
  if (events_ != nullptr) events_->add(Event{now, "", fmt::format("process {} died ({})", p.name(), p.ended)});
  p.end_marked = true;
}

void ProcessExecutive::handle_end(ModuleProcess& p) {
  if (!p.running()) return;
  const bool marked = p.end_marked;
  const std::string ended = p.ended;
  const std::string how = p.reap();  // waits while the kernel frees the process's memory
  if (!marked) {
    mark_end(p, how);
  } else {
    // Its tasks went to ERROR when its life lock came free; the wait status is the last word.
    p.ended = ended;
  }
  p.end_marked = false;
}

void ProcessExecutive::watch_life(ModuleProcess& p, std::uint64_t generation, pid_t pid) {
  if (realtime_) {
    // As the worker's lock holder: woken by a death, it runs ahead of every ordinary thread.
    sched_param lowest{};
    lowest.sched_priority = 1;
    (void)pthread_setschedparam(pthread_self(), SCHED_FIFO, &lowest);
  }
  pthread_mutex_t* life = block_->life(p.index());
  // Blocks until the worker's thread that holds it exits: its death, or its quit.
  const int locked = pthread_mutex_lock(life);
  // What the process ended with, while it is still being torn down (its exit_code in /proc, the
  // wait status as waitid will give it); "" when it cannot be read.
  std::string how;
  {
    // read(2), not a stream: a process already reaped makes the read fail with ESRCH, which
    // libstdc++'s filebuf throws as an exception no iterator catches (it ended the test runner).
    std::string text;
    const std::string path = fmt::format("/proc/{}/stat", pid);
    if (const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC); fd >= 0) {
      std::array<char, 1024> buffer{};
      ssize_t got = 0;
      while ((got = ::read(fd, buffer.data(), buffer.size())) > 0)
        text.append(buffer.data(), static_cast<std::size_t>(got));
      ::close(fd);
    }
    const auto paren = text.rfind(')');
    if (paren != std::string::npos) {
      std::istringstream fields(text.substr(paren + 1));
      std::string field;
      // Fields from the 3rd (state) on: exit_code is the 52nd.
      for (int n = 3; n <= 52 && fields >> field; ++n)
        if (int code = 0; n == 52 && std::from_chars(field.data(), field.data() + field.size(), code).ec == std::errc{})
          how = ModuleProcess::exit_text(code);
    }
  }
  if (locked == EOWNERDEAD) pthread_mutex_consistent(life);
  if (locked == 0 || locked == EOWNERDEAD) pthread_mutex_unlock(life);  // for the next start
  std::lock_guard<std::mutex> lock(p.mutex);
  // Still that start, and an end nobody asked for (a quit reaps it first; a command may have).
  if (p.running() && p.generation() == generation && !p.end_marked && !stopping_.load(std::memory_order_acquire))
    mark_end(p, how.empty() ? std::string("its end not read yet") : how);  // acquire: pairs with shutdown()
}

Result<void> ProcessExecutive::restart(ModuleProcess& p, std::size_t task) {
  if (auto started = start(p); !started) return started;  // the tasks stay in ERROR
  p.ended.clear();
  // Every task that existed before the end is made again in the new process: OFF, as a clear leaves it.
  Result<void> outcome;
  for (const std::size_t i : p.tasks()) {
    if (!tasks_[i]->forget_lost_process()) continue;
    auto spawned = send(p, command_for(ProcessCommandKind::kSignal, i, Signal::kSpawn));
    if (!spawned && (outcome || i == task)) outcome = spawned;
    if (!p.running()) break;  // it ended again at once
  }
  return outcome;
}

Result<void> ProcessExecutive::turn_on_together(const std::vector<std::size_t>& tasks) {
  std::vector<std::size_t> local;
  std::vector<std::vector<std::size_t>> remote(processes_.size());
  for (const std::size_t i : tasks) {
    if (owner_[i] < 0)
      local.push_back(i);
    else
      remote[static_cast<std::size_t>(owner_[i])].push_back(i);
  }
  Result<void> first;
  for (std::size_t k = 0; k < processes_.size(); ++k) {
    if (remote[k].empty()) continue;
    ModuleProcess& p = *processes_[k];
    std::lock_guard<std::mutex> lock(p.mutex);
    ProcessCommand c;
    c.kind = ProcessCommandKind::kTurnOnTogether;
    c.count = static_cast<std::uint32_t>(std::min(remote[k].size(), ProcessCommand::kMaxTasks));
    std::copy_n(remote[k].begin(), c.count, c.tasks.begin());
    auto r = p.running() ? send(p, c) : make_error(Errc::kState, fmt::format("process {} is not running", p.name()));
    if (!r && first) first = r;
  }
  if (!local.empty())
    if (auto r = local_->turn_on_together(local); !r && first) first = r;
  return first;
}

CommitOutcome ProcessExecutive::commit_switch(const SwitchCommit& commit) {
  // One instant for every executive, on the one grid they share: each turns its leaving tasks off
  // after their last release before it, and its joining tasks on for their first release from
  // it. Every leaving task, in every process, is off before any joining one turns on: one writer
  // per variable at any time, as within one process (docs/processes.md). A leave posted late may
  // find its task has run the instant's release: the join part then starts after the last such.
  std::int64_t at_ns = local_->next_commit_ns(commit);
  SwitchCommit local;
  std::vector<SwitchCommit> remote(processes_.size());
  for (const std::size_t i : commit.leaving)
    (owner_[i] < 0 ? local : remote[static_cast<std::size_t>(owner_[i])]).leaving.push_back(i);
  for (const std::size_t i : commit.joining)
    (owner_[i] < 0 ? local : remote[static_cast<std::size_t>(owner_[i])]).joining.push_back(i);
  std::unordered_map<std::string_view, std::uint32_t> index_of;
  for (std::size_t i = 0; i < tasks_.size(); ++i) index_of.emplace(tasks_[i]->name(), static_cast<std::uint32_t>(i));
  std::vector<std::uint32_t> target;
  for (const auto& name : commit.target)
    if (const auto it = index_of.find(name); it != index_of.end()) target.push_back(it->second);

  // Every process's lock, in one order (the supervisor takes one at a time): nothing else talks
  // to a worker while the switch is under way.
  std::vector<std::unique_lock<std::mutex>> locks;
  for (auto& p : processes_) locks.emplace_back(p->mutex);
  CommitOutcome outcome;
  const auto keep = [&outcome](const Result<void>& r) {
    if (!r && outcome.fault) outcome.fault = r;
  };
  for (const SwitchCommit::Part part : {SwitchCommit::Part::kLeave, SwitchCommit::Part::kJoin}) {
    std::vector<bool> posted(processes_.size(), false);
    for (std::size_t k = 0; k < processes_.size(); ++k) {
      ModuleProcess& p = *processes_[k];
      const SwitchCommit& mine = remote[k];
      const bool involved = !mine.leaving.empty() || !mine.joining.empty();
      // The join part tells every running process the new plan (its dispatchers' urgencies).
      if (!p.running()) {
        if (involved) keep(make_error(Errc::kState, fmt::format("process {} is not running", p.name())));
        continue;
      }
      if (part == SwitchCommit::Part::kLeave && !involved) continue;
      ProcessCommand c;
      c.kind = ProcessCommandKind::kCommit;
      c.count = static_cast<std::uint32_t>(std::min(mine.leaving.size(), ProcessCommand::kMaxTasks));
      std::copy_n(mine.leaving.begin(), c.count, c.tasks.begin());
      c.joining_count = static_cast<std::uint32_t>(std::min(mine.joining.size(), ProcessCommand::kMaxTasks));
      std::copy_n(mine.joining.begin(), c.joining_count, c.joining.begin());
      c.target_count = static_cast<std::uint32_t>(std::min(target.size(), ProcessCommand::kMaxTasks));
      std::copy_n(target.begin(), c.target_count, c.target.begin());
      c.at_ns = at_ns;
      c.part = static_cast<std::uint8_t>(part);
      const auto r = p.post(c);
      keep(r);
      posted[k] = r.ok();
      if (p.death_seen()) handle_end(p);
    }
    SwitchCommit here = local;
    here.slow = commit.slow;
    here.target = commit.target;
    here.at_ns = at_ns;
    here.part = part;
    const CommitOutcome mine = local_->commit_switch(here);
    keep(mine.fault);
    std::int64_t joins_from_ns = mine.joins_from_ns;
    for (std::size_t k = 0; k < processes_.size(); ++k) {
      if (!posted[k]) continue;
      std::int64_t theirs = -1;
      keep(processes_[k]->await_answer(&theirs));
      joins_from_ns = std::max(joins_from_ns, theirs);
      if (processes_[k]->death_seen()) handle_end(*processes_[k]);
    }
    at_ns = std::max(at_ns, joins_from_ns);
  }
  outcome.joins_from_ns = at_ns;
  return outcome;
}

Result<void> ProcessExecutive::reinit(std::size_t task) {
  ModuleProcess* p = owner(task);
  if (p == nullptr) return local_->reinit(task);
  std::lock_guard<std::mutex> lock(p->mutex);
  if (!p->running()) return make_error(Errc::kState, fmt::format("process {} is not running", p->name()));
  return send(*p, command_for(ProcessCommandKind::kReinit, task));
}

void ProcessExecutive::shutdown() {
  if (stopped_) return;
  stopped_ = true;
  stopping_.store(true, std::memory_order_release);  // release: the supervisor ends on it
  wake_supervisor();
  if (supervisor_.joinable()) supervisor_.join();
  local_->shutdown();
  // Their tasks are off and killed by now (Subsystem::stop); quit ends each worker in order.
  for (auto& p : processes_) {
    std::lock_guard<std::mutex> lock(p->mutex);
    if (const std::string how = p->stop(); !how.empty())
      spdlog::warn("process {} did not end cleanly ({})", p->name(), how);
  }
  // Every worker has ended, so every watcher's wait is over.
  std::lock_guard<std::mutex> lock(watchers_mutex_);
  for (auto& w : watchers_)
    if (w.joinable()) w.join();
}

void ProcessExecutive::wake_supervisor() const {
  const std::uint64_t one = 1;
  if (wake_fd_ >= 0) (void)!::write(wake_fd_, &one, sizeof one);
}

void ProcessExecutive::supervise() {
  std::vector<Watch> watches;  // this thread's: one per start of a process, until its end is handled
  std::vector<pollfd> fds;
  while (!stopping_.load(std::memory_order_acquire)) {  // acquire: pairs with shutdown()
    for (auto& p : processes_) {
      Watch w{p.get(), 0, -1, false, -1};
      w.pidfd = p->take_watch(w.generation, w.pid);
      if (w.pidfd >= 0) watches.push_back(w);
    }
    fds.assign(1, pollfd{wake_fd_, POLLIN, 0});
    for (const Watch& w : watches) fds.push_back(pollfd{w.pidfd, POLLIN, 0});
    // The heartbeat needs a tick while any process runs; without an eventfd, look again now and
    // then for processes started since.
    const int timeout_ms = !watches.empty() || wake_fd_ < 0 ? kHeartbeatTickMs : -1;
    const int ready = ::poll(fds.data(), fds.size(), timeout_ms);
    if (ready > 0 && (fds[0].revents & POLLIN) != 0) {
      std::uint64_t count = 0;
      (void)!::read(wake_fd_, &count, sizeof count);
    }
    for (std::size_t j = watches.size(); j-- > 0;) {
      if (ready <= 0 || (fds[j + 1].revents & POLLIN) == 0) continue;
      Watch& w = watches[j];
      {
        std::lock_guard<std::mutex> lock(w.process->mutex);
        // Still the start this descriptor names, and not handled yet (a command may have).
        if (w.process->running() && w.process->generation() == w.generation) handle_end(*w.process);
      }
      ::close(w.pidfd);
      watches.erase(watches.begin() + static_cast<std::ptrdiff_t>(j));
    }
    check_heartbeats(watches);
  }
  for (const Watch& w : watches) ::close(w.pidfd);
}

void ProcessExecutive::check_stopped(Watch& w, std::int64_t now_ns) {
  if (w.pid <= 0) return;
  if (process_state(w.pid) != 'T') {
    w.stopped_since_ns = -1;
    return;
  }
  if (w.stopped_since_ns < 0) {
    w.stopped_since_ns = now_ns;
    return;
  }
  std::int64_t bound = StuckBound::kMethodNs;
  for (const std::size_t i : w.process->tasks()) bound = std::min(bound, stuck_bound_ns(*tasks_[i], BusyIn::kCycle));
  const std::int64_t stopped = now_ns - w.stopped_since_ns;
  if (stopped <= bound) return;
  const std::string reason =
      fmt::format("stopped by a signal for {:.0f} ms, its tasks running nothing", static_cast<double>(stopped) / 1e6);
  w.process->note_kill(w.generation, reason);
  // SIGKILL ends a stopped process too (SIGCONT is not needed), by the supervisor's own pidfd.
  ::syscall(SYS_pidfd_send_signal, w.pidfd, SIGKILL, nullptr, 0);
  w.killed = true;
  if (events_ != nullptr)
    events_->add(Event{now_ns, "", fmt::format("process {}: {}; killed", w.process->name(), reason)});
}

std::int64_t ProcessExecutive::stuck_bound_ns(const Task& task, BusyIn method) {
  return StuckBound::of(method, task.period_ns(), task.spec().deadline_ns);
}

void ProcessExecutive::check_heartbeats(std::vector<Watch>& watches) {
  const std::int64_t now = now_ns();
  for (Watch& w : watches) {
    if (!w.killed) check_stopped(w, now);
    if (w.killed) continue;
    for (const std::size_t i : w.process->tasks()) {
      const TaskShared& slot = *block_->slot(i);
      const std::int64_t since = slot.busy_since_ns.load(std::memory_order_acquire);  // acquire: pairs with BusyScope
      if (since <= TaskShared::kGivenUp) continue;                         // idle (a module process gives nothing up)
      const BusyIn method = slot.busy_in.load(std::memory_order_relaxed);  // ordered by the acquire above
      const std::int64_t busy = now - since;
      if (busy <= stuck_bound_ns(*tasks_[i], method)) continue;
      const std::string reason = fmt::format("{} stuck in {}() for {:.0f} ms", tasks_[i]->name(), busy_in_name(method),
                                             static_cast<double>(busy) / 1e6);
      w.process->note_kill(w.generation, reason);
      // By the supervisor's own pidfd: only ever this start of the process.
      ::syscall(SYS_pidfd_send_signal, w.pidfd, SIGKILL, nullptr, 0);
      w.killed = true;
      if (events_ != nullptr)
        events_->add(Event{now, "", fmt::format("process {}: {}; killed", w.process->name(), reason)});
      break;
    }
  }
}

}  // namespace chimera
