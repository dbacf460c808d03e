#pragma once
// The real clock: one thread per task, from spawn to kill, pinned to the task's CPU, with
// SCHED_FIFO priorities where the system allows: fixed by the policy's order under rm and dm,
// set at each release by the CPU's priority dispatcher under edf and muf. Periodic releases are
// at absolute times epoch + k * period (no drift); aperiodic tasks wake on their trigger, within
// their sporadic server's budget. Signals travel through a one-slot mailbox per task: the
// control thread posts and waits; the task's thread carries the signal out between cycles and
// never waits for the control thread. A service thread carries out the modules' switch requests
// and watches for jobs running past their deadline (service_thread.cpp).

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "chimera/analysis/release_order.hpp"
#include "executive.hpp"
#include "schedule_plan.hpp"

namespace chimera {

struct Worker;
struct TaskThread;
struct Mail;
class PriorityDispatcher;

class RealExecutive final : public Executive {
 public:
  explicit RealExecutive(ExecutiveSetup setup);
  ~RealExecutive() override;
  RealExecutive(const RealExecutive&) = delete;
  RealExecutive& operator=(const RealExecutive&) = delete;
  RealExecutive(RealExecutive&&) = delete;
  RealExecutive& operator=(RealExecutive&&) = delete;

  // Executive.
  [[nodiscard]] ClockKind clock() const noexcept override { return ClockKind::kReal; }
  [[nodiscard]] std::int64_t now_ns() const override;
  [[nodiscard]] int cpu_of(std::size_t task) const override { return cpus_[task]; }
  Result<void> signal(std::size_t index, Signal sig) override;
  Result<void> turn_on_together(const std::vector<std::size_t>& indices) override;
  CommitOutcome commit_switch(const SwitchCommit& commit) override;
  /// The instant a switch posted now would commit at (SwitchCommit::at_ns). Not real-time safe.
  [[nodiscard]] std::int64_t next_commit_ns(const SwitchCommit& commit) const;
  Result<void> reinit(std::size_t index) override;
  void run_for(std::int64_t ns) override;
  void serve(ServiceHooks hooks) override;
  void stop_serving() override;
  void variable_written(VarIndex v) override;
  void shutdown() override;
  void begin_stop() override;
  [[nodiscard]] std::vector<std::string> left_behind() const override;
  void watch_writes(VarIndex v, WriteWatch* watch) override;
  /// The watch of variable `v`, if any. Real-time safe.
  [[nodiscard]] WriteWatch* watch_of(int v) const noexcept {
    return watches_[static_cast<std::size_t>(v)].load(std::memory_order_acquire);  // acquire: the watch is whole
  }

  /// CLOCK_MONOTONIC at the executive's time 0. Real-time safe.
  [[nodiscard]] std::int64_t epoch_ns() const noexcept { return epoch_ns_; }
  [[nodiscard]] const GlobalTable& table() const { return *table_; }
  /// The SCHED_FIFO priority task `index` starts at (its fixed priority under rm and dm).
  [[nodiscard]] int fixed_priority(std::size_t index) const;
  /// Aperiodic task `index`'s bell (an eventfd), -1 for a periodic task: what a module process is
  /// given to wake it by (ExecutiveSetup::bell_fds). Any thread.
  [[nodiscard]] int bell_fd(std::size_t index) const;
  /// Whether this process runs task `index` (ExecutiveSetup::hosted). Any thread.
  [[nodiscard]] bool hosts(std::size_t index) const noexcept { return hosted_.empty() || hosted_[index]; }
  /// The absolute deadline (executive clock) of the job task `index` is running now, if it is
  /// running one with a deadline; it names the job. Any thread; wait-free.
  [[nodiscard]] std::optional<std::int64_t> running_deadline(std::size_t index) const noexcept;

  /// How often the service thread looks for jobs running past their deadline.
  static constexpr std::int64_t kWatchTickNs = 5'000'000;

 private:
  void make_workers(const SchedulePlan& plan, const std::vector<int>& bell_fds);
  void link_workers();
  void make_dispatchers(const SchedulePlan& plan);
  void form_threads();
  /// Starts `thread`, whose members `alive` are spawned already (a watch's move), 0 otherwise.
  Result<void> start_thread(TaskThread& thread, int alive = 0) const;
  /// Posts `mail` to a task's thread and waits for its answer.
  Result<void> post(Worker& w, Mail mail);
  /// Posts `mail` to several tasks' threads at once, then waits for every answer.
  Result<void> post_all(const std::vector<std::size_t>& indices, const std::vector<Mail>& mails);
  /// Tells the successors of the joining tasks the release each joins at: its first from `from_ns`.
  void publish_joins(const std::vector<std::size_t>& joining, std::int64_t from_ns);
  /// Posts only; returns the sequence number of the answer to wait for.
  static std::uint32_t send(Worker& w, const Mail& mail);
  Result<void> await(Worker& w, std::uint32_t seq) const;
  /// Refuses at once a mail to a task whose thread left an earlier one unanswered and has not
  /// caught up since (a method is stuck): a second wait would only add to the first.
  static Result<void> answering(Worker& w);
  /// New urgency data (MUF's critical set after a switch) for the edf / muf dispatchers.
  void set_plan(SchedulePlan plan);
  /// The service thread's body, and one look at every task's running job (service_thread.cpp).
  void service_main(const ServiceHooks& hooks);
  void watch_overruns();
  /// The stuck-task watch (stuck_methods.cpp), in the main process only: a task of this process
  /// inside one module method longer than StuckBound is ERROR, its thread-mates move to a new
  /// thread, and its own thread drops to SCHED_IDLE. The service thread's.
  void give_up_stuck_methods();
  void give_up(Worker& w, const Task::Busy& busy, std::int64_t now_ns);
  /// A given-up thread back at SCHED_IDLE, should a dispatcher's ranking have raised it again.
  void keep_given_up_idle();

  const ResolvedSubsystem& subsystem_;
  GlobalTable* table_;
  EventLog* events_;
  std::vector<Task*> tasks_;
  const std::vector<bool> hosted_;  // empty: every task
  analysis::ReleaseOrder order_;
  SchedulePlan plan_;
  const std::vector<int> cpus_;  // plan_.cpu as it was made: a switch never moves a task, so any thread may read it
  std::vector<std::unique_ptr<PriorityDispatcher>> dispatchers_;  // stopped by shutdown(), before the workers go
  std::vector<std::unique_ptr<Worker>> workers_;
  std::vector<std::unique_ptr<TaskThread>> threads_;
  std::int64_t epoch_ns_ = 0;
  bool realtime_ = false;
  std::mutex control_mutex_;                        // one control request at a time; never taken by a task's thread
  std::vector<std::atomic<WriteWatch*>> watches_;   // one a variable of the table, nullptr: none; never resized
  std::int64_t reply_timeout_ns_ = 10'000'000'000;  // the control thread's: how long a signal waits for its answer

  // The service thread (service_thread.cpp) and what its overrun watch holds.
  std::thread service_;
  std::atomic<bool> service_stop_{false};
  Doorbell* service_bell_ = nullptr;  // what the service thread sleeps on: the requests' bell, or own_bell_
  Doorbell own_bell_;
  // Per task: the deadline of the job last reported overdue, and whether that job holds the
  // illegal-configuration flag (a hard task's). The service thread's own.
  std::vector<std::int64_t> overdue_reported_;
  std::vector<bool> overdue_hold_;
  bool gave_up_any_ = false;         // the service thread's: a stuck method was given up (stuck_methods.cpp)
  std::int64_t stopped_at_ns_ = -1;  // after shutdown()
};

/// Asks for mlockall and reports, once per process, when real-time facilities are refused.
void prepare_realtime_process(bool realtime);

/// Rings an aperiodic worker's bell (eventfd). Real-time safe (one write system call).
void ring_bell(const Worker& w) noexcept;

}  // namespace chimera
