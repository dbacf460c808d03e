#pragma once
// The executive of a file with module processes (docs/processes.md): the main process's real
// executive runs the tasks of `main`; each module process runs its tasks with a real executive of
// its own, started by fork and exec of the chimera binary. This class copies no executive: it
// routes each request to the process that runs the task (the main process's RealExecutive, or a
// worker over its command socket), and supervises the workers: a thread polls their pidfds, and
// when one ends its tasks go to ERROR with the reason and hold the illegal-configuration flag;
// `clear` starts the process again. Private to the exec part. Nothing here is real-time safe.

#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "executive.hpp"
#include "module_process.hpp"
#include "real_executive.hpp"
#include "task_block.hpp"

namespace chimera {

class ProcessExecutive final : public Executive {
 public:
  explicit ProcessExecutive(ExecutiveSetup setup);
  ~ProcessExecutive() override;
  ProcessExecutive(const ProcessExecutive&) = delete;
  ProcessExecutive& operator=(const ProcessExecutive&) = delete;
  ProcessExecutive(ProcessExecutive&&) = delete;
  ProcessExecutive& operator=(ProcessExecutive&&) = delete;

  [[nodiscard]] ClockKind clock() const noexcept override { return ClockKind::kReal; }
  [[nodiscard]] std::int64_t now_ns() const override { return local_->now_ns(); }
  [[nodiscard]] int cpu_of(std::size_t task) const override { return local_->cpu_of(task); }
  Result<void> signal(std::size_t task, Signal signal) override;
  Result<void> turn_on_together(const std::vector<std::size_t>& tasks) override;
  CommitOutcome commit_switch(const SwitchCommit& commit) override;
  Result<void> reinit(std::size_t task) override;
  void run_for(std::int64_t ns) override { local_->run_for(ns); }
  void serve(ServiceHooks hooks) override { local_->serve(std::move(hooks)); }
  void stop_serving() override { local_->stop_serving(); }
  void variable_written(VarIndex v) override { local_->variable_written(v); }
  void shutdown() override;
  void begin_stop() override { local_->begin_stop(); }  // a module process's stuck task: its process is killed
  [[nodiscard]] std::vector<std::string> left_behind() const override { return local_->left_behind(); }
  // Only the tasks of the main process: a worker's publications are found by the watcher's own poll.
  void watch_writes(VarIndex v, WriteWatch* watch) override { local_->watch_writes(v, watch); }

 private:
  /// The module process that runs task `task`, or nullptr for the main process.
  [[nodiscard]] ModuleProcess* owner(std::size_t task) const;
  /// Sends one command to process `p` (its mutex held), handling its end if it ends meanwhile.
  Result<void> send(ModuleProcess& p, const ProcessCommand& command);
  /// Process `p` has ended (its mutex held): reaped, and its tasks to ERROR with the reason
  /// unless its life lock's watcher put them there already.
  void handle_end(ModuleProcess& p);
  /// Its tasks to ERROR with `how` it ended, the flag held, an event (its mutex held).
  void mark_end(ModuleProcess& p, const std::string& how);
  /// A watcher thread's body, one per start of a process: waits on its life lock, which the
  /// kernel frees as the process dies, and marks the end at once (docs/processes.md).
  void watch_life(ModuleProcess& p, std::uint64_t generation, pid_t pid);
  /// `clear` of a task of ended process `p` (its mutex held): the process again, its tasks spawned.
  Result<void> restart(ModuleProcess& p, std::size_t task);
  Result<void> start(ModuleProcess& p);
  /// One start of a module process as the supervisor watches it, through a pidfd of its own.
  struct Watch {
    ModuleProcess* process;
    std::uint64_t generation;
    int pidfd;
    bool killed;                         // for a stuck task: its end is on the way
    pid_t pid;                           // to read its state in /proc; signals go by the pidfd
    std::int64_t stopped_since_ns = -1;  // first seen stopped (SIGSTOP), -1 while it runs
  };
  /// A process stopped by a signal (SIGSTOP, SIGTSTP) runs none of its tasks, yet no heartbeat
  /// says so between methods: past the stuck bound of its shortest period it is killed, as a stuck
  /// task's is. A debugger's stop (traced) is left alone.
  void check_stopped(Watch& w, std::int64_t now_ns);
  /// How often the supervisor reads the heartbeats; a task inside one method longer than
  /// StuckBound (task_shared.hpp) is stuck.
  static constexpr int kHeartbeatTickMs = 10;
  [[nodiscard]] static std::int64_t stuck_bound_ns(const Task& task, BusyIn method);
  /// The supervisor thread's body: poll every running process's pidfd, and every tick look at
  /// their tasks' heartbeats.
  void supervise();
  /// Kills each process with a task stuck in a method (docs/processes.md). Supervisor thread.
  void check_heartbeats(std::vector<Watch>& watches);
  void wake_supervisor() const;

  std::vector<Task*> tasks_;
  EventLog* events_;
  bool realtime_;  // SCHED_FIFO wanted: the life watchers take the lowest real-time priority
  TaskBlock* block_;
  WorkerLaunch launch_;
  std::unique_ptr<RealExecutive> local_;  // the tasks of main
  std::vector<std::unique_ptr<ModuleProcess>> processes_;
  std::vector<int> owner_;  // per task: its index in processes_, -1 for main
  int wake_fd_ = -1;        // eventfd: the set of processes changed, or stop
  std::atomic<bool> stopping_{false};
  std::thread supervisor_;
  std::mutex watchers_mutex_;
  std::vector<std::thread> watchers_;  // one per start of a module process, joined at shutdown
  bool stopped_ = false;               // the control thread's
};

}  // namespace chimera
