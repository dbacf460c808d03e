#include "module_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

#include <fmt/format.h>

namespace chimera {

namespace {

// Generous bounds: a worker loads its plugins before it is ready, and an init may take long; a
// death is seen at once through the pidfd whatever the bound.
constexpr int kReadyTimeoutMs = 30'000;
constexpr int kReplyTimeoutMs = 20'000;
constexpr int kQuitTimeoutMs = 10'000;

Error sys_error(const std::string& process, std::string_view what) {
  return make_error(Errc::kSystem,
                    fmt::format("process {}: {} failed: {}", process, what, std::generic_category().message(errno)));
}

int pidfd_open(pid_t pid) { return static_cast<int>(::syscall(SYS_pidfd_open, pid, 0)); }

std::string signal_text(int sig) {
  const char* abbrev = ::sigabbrev_np(sig);
  return abbrev != nullptr ? fmt::format("SIG{}", abbrev) : fmt::format("signal {}", sig);
}

}  // namespace

ModuleProcess::ModuleProcess(std::string name, std::vector<std::size_t> tasks, std::size_t index)
    : name_(std::move(name)), tasks_(std::move(tasks)), index_(index) {}

ModuleProcess::~ModuleProcess() {
  if (running()) (void)stop();
  close_fds();
  if (unwatched_fd_ >= 0) ::close(unwatched_fd_);
}

int ModuleProcess::take_watch(std::uint64_t& generation, pid_t& pid) {
  std::lock_guard<std::mutex> lock(watch_mutex_);
  generation = unwatched_generation_;
  pid = unwatched_pid_;
  return std::exchange(unwatched_fd_, -1);
}

void ModuleProcess::note_kill(std::uint64_t generation, std::string reason) {
  std::lock_guard<std::mutex> lock(watch_mutex_);
  killed_generation_ = generation;
  kill_reason_ = std::move(reason);
}

std::string ModuleProcess::kill_reason() const {
  std::lock_guard<std::mutex> lock(watch_mutex_);
  return killed_generation_ == generation() ? kill_reason_ : std::string();
}

void ModuleProcess::close_fds() noexcept {
  if (socket_ >= 0) ::close(socket_);
  if (const int fd = pidfd_.exchange(-1, std::memory_order_acq_rel); fd >= 0) ::close(fd);  // acq_rel: as in start()
  socket_ = -1;
}

Result<void> ModuleProcess::start(const WorkerLaunch& launch) {
  int pair[2] = {-1, -1};
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, pair) != 0) return sys_error(name_, "socketpair");
  // Everything the child needs is made before the fork: after it, only async-signal-safe calls.
  std::vector<std::string> args{launch.program, "__worker"};
  args.insert(args.end(), launch.args.begin(), launch.args.end());
  args.insert(args.end(), {"--process", name_, "--socket-fd", std::to_string(pair[1]), "--block-fd",
                           std::to_string(launch.block_fd), "--life", std::to_string(index_)});
  if (launch.history_fd >= 0) args.insert(args.end(), {"--history-fd", std::to_string(launch.history_fd)});
  for (const auto& [task, fd] : launch.bells) args.insert(args.end(), {"--bell", fmt::format("{}:{}", task, fd)});
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(pair[0]);
    ::close(pair[1]);
    return sys_error(name_, "fork");
  }
  if (pid == 0) {
    // The child: the two descriptors it needs survive the exec; its own process group keeps a
    // terminal's Ctrl-C for the main process, which stops it in order; no signal stays blocked.
    ::fcntl(pair[1], F_SETFD, 0);
    ::fcntl(launch.block_fd, F_SETFD, 0);
    if (launch.history_fd >= 0) ::fcntl(launch.history_fd, F_SETFD, 0);
    for (const auto& bell : launch.bells) ::fcntl(bell.second, F_SETFD, 0);
    ::setpgid(0, 0);
    sigset_t none;
    ::sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(pair[1]);
  pid_ = pid;
  socket_ = pair[0];
  pidfd_.store(pidfd_open(pid), std::memory_order_release);  // release: the supervisor polls it once running
  if (pidfd() < 0) {
    const Error e = sys_error(name_, "pidfd_open");
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    close_fds();
    return e;
  }
  death_seen_ = false;
  const std::uint64_t generation =
      generation_.fetch_add(1, std::memory_order_acq_rel) + 1;  // acq_rel: one order of starts
  {
    // The supervisor's own descriptor of this start: it can never name a later process.
    std::lock_guard<std::mutex> lock(watch_mutex_);
    if (unwatched_fd_ >= 0) ::close(unwatched_fd_);  // a start that ended before the supervisor took it
    unwatched_fd_ = ::fcntl(pidfd(), F_DUPFD_CLOEXEC, 0);
    unwatched_generation_ = generation;
    unwatched_pid_ = pid;
  }
  state_.store(State::kRunning, std::memory_order_release);  // release: the fds are set for the supervisor
  ProcessReply ready;
  if (auto r = await_reply(ready, kReadyTimeoutMs); !r) {
    if (death_seen_) {
      return make_error(Errc::kSystem, fmt::format("process {} ended before it was ready ({})", name_, reap()));
    }
    (void)stop();
    return r;
  }
  if (auto r = ready.result(); !r) {
    (void)stop();
    return make_error(r.error().code, fmt::format("process {}: {}", name_, r.error().message));
  }
  return {};
}

Result<void> ModuleProcess::await_reply(ProcessReply& reply, std::int64_t timeout_ms) {
  pollfd fds[2] = {{socket_, POLLIN, 0}, {pidfd(), POLLIN, 0}};
  for (;;) {
    const int n = ::poll(fds, 2, static_cast<int>(timeout_ms));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return sys_error(name_, "poll");
    if (n == 0)
      return make_error(Errc::kSystem,
                        fmt::format("process {}: no answer within {} s (stuck?)", name_, timeout_ms / 1000));
    // A reply sent just before the end is still an answer: read it first.
    if ((fds[0].revents & POLLIN) != 0) {
      const ssize_t got = ::recv(socket_, &reply, sizeof reply, 0);
      if (got == static_cast<ssize_t>(sizeof reply)) return {};
    }
    if ((fds[1].revents & POLLIN) != 0 || (fds[0].revents & (POLLHUP | POLLERR)) != 0) {
      // The socket closes as the process ends; its pidfd says so for certain.
      pollfd pid_only{pidfd(), POLLIN, 0};
      if (::poll(&pid_only, 1, kReplyTimeoutMs) > 0) {
        death_seen_ = true;
        return make_error(Errc::kSystem, fmt::format("process {} has ended", name_));
      }
      return make_error(Errc::kSystem, fmt::format("process {} closed its command socket", name_));
    }
  }
}

Result<void> ModuleProcess::command(const ProcessCommand& command) {
  if (auto posted = post(command); !posted) return posted;
  return await_answer();
}

Result<void> ModuleProcess::await_answer(std::int64_t* value) {
  ProcessReply reply;
  if (auto r = await_reply(reply, kReplyTimeoutMs); !r) return r;
  if (value != nullptr) *value = reply.value;
  return reply.result();
}

Result<void> ModuleProcess::post(const ProcessCommand& command) {
  if (!running()) return make_error(Errc::kState, fmt::format("process {} is not running", name_));
  if (::send(socket_, &command, sizeof command, MSG_NOSIGNAL) != static_cast<ssize_t>(sizeof command)) {
    if (errno == EPIPE || errno == ECONNRESET) {
      pollfd pid_only{pidfd(), POLLIN, 0};
      death_seen_ = ::poll(&pid_only, 1, kReplyTimeoutMs) > 0;
      return make_error(Errc::kSystem, fmt::format("process {} has ended", name_));
    }
    return sys_error(name_, "send");
  }
  return {};
}

std::string ModuleProcess::reap() {
  siginfo_t info{};
  int rc = -1;
  do {
    rc = ::waitid(P_PIDFD, static_cast<id_t>(pidfd()), &info, WEXITED);
  } while (rc != 0 && errno == EINTR);
  state_.store(State::kEnded, std::memory_order_release);  // release: as in start()
  close_fds();
  pid_ = -1;
  death_seen_ = false;
  end_marked = false;
  if (rc != 0) return fmt::format("its end could not be read: {}", std::generic_category().message(errno));
  switch (info.si_code) {
    case CLD_EXITED: return fmt::format("exited with code {}", info.si_status);
    case CLD_KILLED: return fmt::format("killed by {}", signal_text(info.si_status));
    case CLD_DUMPED: return fmt::format("killed by {} (core dumped)", signal_text(info.si_status));
    default: return fmt::format("ended (wait code {}, status {})", info.si_code, info.si_status);
  }
}

std::string ModuleProcess::exit_text(int status) {
  if (WIFEXITED(status)) return fmt::format("exited with code {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status))
    return WCOREDUMP(status) ? fmt::format("killed by {} (core dumped)", signal_text(WTERMSIG(status)))
                             : fmt::format("killed by {}", signal_text(WTERMSIG(status)));
  return fmt::format("ended (status {})", status);
}

std::string ModuleProcess::stop() {
  if (!running()) return {};
  ProcessCommand quit;
  quit.kind = ProcessCommandKind::kQuit;
  const bool sent = ::send(socket_, &quit, sizeof quit, MSG_NOSIGNAL) == static_cast<ssize_t>(sizeof quit);
  pollfd pid_only{pidfd(), POLLIN, 0};
  if (!sent || ::poll(&pid_only, 1, kQuitTimeoutMs) <= 0) {
    ::syscall(SYS_pidfd_send_signal, pidfd(), SIGKILL, nullptr, 0);  // by pidfd: never a reused pid
  }
  std::string how = reap();
  return how == "exited with code 0" ? std::string() : how;
}

}  // namespace chimera
