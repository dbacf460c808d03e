#pragma once
// The main process's handle on one module process (docs/processes.md): starting it (fork, then
// exec of the chimera binary in its worker mode), its pidfd, the command socket, and what its end
// says about why it ended. Private to the process executive. Not real-time safe.

#include <sys/types.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "chimera/core/result.hpp"
#include "process_protocol.hpp"

namespace chimera {

/// How to start a worker: the program and the arguments that every worker of the run shares.
struct WorkerLaunch {
  std::string program;            // the chimera binary
  std::vector<std::string> args;  // after the worker mode's name; --process, --socket-fd follow
  int block_fd = -1;              // the task block's memfd, inherited at this number
  int history_fd = -1;            // the flight recorder's rings (a memfd), inherited likewise; -1: none
  std::vector<std::pair<std::size_t, int>> bells;  // aperiodic tasks' eventfds (task, fd), inherited likewise
};

class ModuleProcess {
 public:
  /// `index`: its life lock in the task block (TaskBlock::life).
  ModuleProcess(std::string name, std::vector<std::size_t> tasks, std::size_t index);
  ~ModuleProcess();
  ModuleProcess(const ModuleProcess&) = delete;
  ModuleProcess& operator=(const ModuleProcess&) = delete;
  ModuleProcess(ModuleProcess&&) = delete;
  ModuleProcess& operator=(ModuleProcess&&) = delete;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] std::size_t index() const noexcept { return index_; }
  /// The running start's pid (-1 when none); under `mutex`.
  [[nodiscard]] pid_t pid() const noexcept { return pid_; }
  /// Its tasks' indices in the file, in file order.
  [[nodiscard]] const std::vector<std::size_t>& tasks() const noexcept { return tasks_; }

  /// Starts the process and waits until it says it is ready (attached, its tasks made) or ends.
  /// A process that ends before it is ready is reaped here and the error says why.
  Result<void> start(const WorkerLaunch& launch);
  /// Sends `command` and waits for its reply, or for the process to end (then death_seen()).
  Result<void> command(const ProcessCommand& command);
  /// command() in two halves, so that several processes carry out one command at once: post()
  /// sends, await_answer() waits for its reply (or the end). A failed post needs no await.
  Result<void> post(const ProcessCommand& command);
  /// `value`, when given, receives the reply's value (ProcessReply::value), even with an error.
  Result<void> await_answer(std::int64_t* value = nullptr);
  /// Whether the process is running: started, and not seen to end.
  [[nodiscard]] bool running() const noexcept { return state_.load(std::memory_order_acquire) == State::kRunning; }
  /// Whether its end has been seen but not yet reaped.
  [[nodiscard]] bool death_seen() const noexcept { return death_seen_; }
  /// The pidfd (readable once the process ended), -1 when not running.
  [[nodiscard]] int pidfd() const noexcept { return pidfd_.load(std::memory_order_acquire); }
  /// Reaps the ended process and says how it ended: "killed by SIGSEGV (core dumped)",
  /// "exited with code 3". Not running afterwards.
  std::string reap();
  /// How a wait status reads in reap()'s words ("killed by SIGSEGV", "exited with code 3").
  static std::string exit_text(int status);
  /// Asks it to quit (its tasks off and killed) and waits a bounded time, then kills it; reaps.
  /// Returns how it ended when that was not a clean exit ("" when it was).
  std::string stop();

  /// The supervisor's own pidfd of the process started last (a duplicate, which names that
  /// process and no other for as long as it is open), that start's number and its pid; -1 when
  /// taken already. The caller owns the descriptor. Any thread.
  int take_watch(std::uint64_t& generation, pid_t& pid);
  /// Which start of the process it is (1 for the first); changes only under `mutex`.
  [[nodiscard]] std::uint64_t generation() const noexcept { return generation_.load(std::memory_order_acquire); }
  /// The supervisor is about to kill start `generation` of the process, for `reason`: the end
  /// that follows is told with it. Any thread.
  void note_kill(std::uint64_t generation, std::string reason);
  /// Why the supervisor killed the start running now, "" if it did not; under `mutex`.
  [[nodiscard]] std::string kill_reason() const;

  /// Held by whoever sends a command or handles the process's end: one at a time.
  std::mutex mutex;
  /// How it last ended unasked ("killed by SIGSEGV"), "" while it runs or was never started;
  /// under `mutex`, the process executive's.
  std::string ended;
  /// Its death has been seen by its life lock and its tasks are in ERROR, but it is not reaped
  /// yet (the kernel is still freeing its memory); under `mutex`.
  bool end_marked = false;

 private:
  enum class State : std::uint8_t { kNotStarted, kRunning, kEnded };
  Result<void> await_reply(ProcessReply& reply, std::int64_t timeout_ms);
  void close_fds() noexcept;

  std::string name_;
  std::vector<std::size_t> tasks_;
  std::size_t index_;
  pid_t pid_ = -1;
  std::atomic<int> pidfd_{-1};  // read by the supervisor without the mutex (acquire: see start())
  int socket_ = -1;
  bool death_seen_ = false;
  std::atomic<State> state_{State::kNotStarted};  // read by the supervisor without the mutex
  std::atomic<std::uint64_t> generation_{0};      // read by the supervisor without the mutex
  // What passes between the starter and the supervisor without `mutex` (held only to copy).
  mutable std::mutex watch_mutex_;
  int unwatched_fd_ = -1;
  std::uint64_t unwatched_generation_ = 0;
  pid_t unwatched_pid_ = -1;
  std::uint64_t killed_generation_ = 0;
  std::string kill_reason_;
};

}  // namespace chimera
