#pragma once
// The real clock: one thread per task, from spawn to kill, pinned to the task's CPU, with
// SCHED_FIFO priorities where the system allows: fixed by the policy's order under rm and dm,
// set at each release by the CPU's priority dispatcher under edf and muf. Periodic releases are
// at absolute times epoch + k * period (no drift); aperiodic tasks wake on their trigger, within
// their sporadic server's budget. Signals travel through a one-slot mailbox per task: the
// control thread posts and waits; the task's thread carries the signal out between cycles and
// never waits for the control thread.

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "chimera/exec/task.hpp"
#include "chimera/svt/global_table.hpp"
#include "release_order.hpp"
#include "schedule_plan.hpp"

namespace chimera {

struct Worker;
struct TaskThread;
struct Mail;
class PriorityDispatcher;

class RealExecutive {
 public:
  RealExecutive(const std::vector<Task*>& tasks, const ReleaseOrder& order, const SchedulePlan& plan, bool realtime,
                const GlobalTable& table);
  ~RealExecutive();
  RealExecutive(const RealExecutive&) = delete;
  RealExecutive& operator=(const RealExecutive&) = delete;

  /// Time since the executive's epoch on CLOCK_MONOTONIC.
  [[nodiscard]] std::int64_t now_ns() const;
  [[nodiscard]] std::int64_t epoch_ns() const { return epoch_ns_; }
  [[nodiscard]] const GlobalTable& table() const { return table_; }
  /// Whether real-time priorities were asked for (they may still have been refused).
  [[nodiscard]] bool realtime() const { return realtime_; }
  /// Carries out a signal on the task's own thread (started by spawn, ended by kill) and
  /// waits for it. Not real-time safe; never blocks a task's thread.
  Result<void> signal(std::size_t index, Signal sig);
  /// Turns on the tasks `indices` (OFF) as one: on() on each task's thread, then every one's
  /// first release at its first grid point at or after one common instant, so that none runs a
  /// release before all are on. Not real-time safe.
  Result<void> turn_on_together(const std::vector<std::size_t>& indices, std::int64_t not_before_ns = 0);
  /// A switch's commit (docs/reconfiguration.md): every task of `leaving` (ON) turns off after its
  /// last release before `commit_ns` (subsystem clock); then every task of `joining` (OFF) turns
  /// on, first released at its first grid point at or after `commit_ns` (later only if the
  /// leaving took longer). The other tasks run on untouched. Not real-time safe.
  Result<void> commit_switch(const std::vector<std::size_t>& leaving, const std::vector<std::size_t>& joining,
                             std::int64_t commit_ns);
  /// New urgency data (MUF's critical set after a switch) for the edf / muf dispatchers; fixed
  /// priorities depend on periods and deadlines only and stay. Not real-time safe.
  void set_plan(const SchedulePlan& plan);
  /// reinit() on the task's own thread, between two of its cycles. Not real-time safe.
  Result<void> reinit(std::size_t index);
  /// Someone other than a task wrote variable `v` (the operator's `set`): wakes the aperiodic
  /// tasks triggered by it. Not real-time safe.
  void variable_written(VarIndex v);
  /// The absolute deadline (executive clock) of the job task `index` is running now, if it is
  /// running one with a deadline; it names the job. Any thread; wait-free.
  [[nodiscard]] std::optional<std::int64_t> running_deadline(std::size_t index) const noexcept;
  /// The SCHED_FIFO priority task `index` starts at (its fixed priority under rm and dm).
  [[nodiscard]] int fixed_priority(std::size_t index) const;

 private:
  void make_workers(const std::vector<Task*>& tasks, const SchedulePlan& plan);
  void link_workers(const ReleaseOrder& order);
  void make_dispatchers(const SchedulePlan& plan);
  void form_threads(const ReleaseOrder& order);
  Result<void> start_thread(TaskThread& thread) const;
  /// Posts `mail` to a task's thread and waits for its answer. Not real-time safe.
  static Result<void> post(Worker& w, Mail mail);
  /// Posts `mail` to several tasks' threads at once, then waits for every answer.
  Result<void> post_all(const std::vector<std::size_t>& indices, const std::vector<Mail>& mails);
  /// Posts only; returns the sequence number of the answer to wait for.
  static std::uint32_t send(Worker& w, const Mail& mail);
  static Result<void> await(Worker& w, std::uint32_t seq);
  Result<void> turn_on_locked(const std::vector<std::size_t>& indices, std::int64_t not_before_ns);

  std::vector<std::unique_ptr<PriorityDispatcher>> dispatchers_;  // outlive the workers that poke them
  std::vector<std::unique_ptr<Worker>> workers_;
  std::vector<std::unique_ptr<TaskThread>> threads_;
  const GlobalTable& table_;
  std::int64_t epoch_ns_ = 0;
  bool realtime_ = false;
  std::mutex control_mutex_;  // one control request at a time; never taken by a task's thread
};

/// Asks for mlockall and reports, once per process, when real-time facilities are refused.
void prepare_realtime_process(bool realtime);

/// Rings an aperiodic worker's bell (eventfd). Real-time safe (one write system call).
void ring_bell(const Worker& w) noexcept;

}  // namespace chimera
