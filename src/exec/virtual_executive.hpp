#pragma once
// The virtual clock: the subsystem's schedule simulated on simulated time by the calling thread,
// deterministically and as fast as the machine allows. It is a discrete-event simulation of the
// real executive: each task on its CPU, jobs released at whole multiples of the period (or by
// their trigger, for aperiodic tasks), preemptive, in the order the file's policy gives
// (urgency.hpp), the same-rate data-flow rule, sporadic servers, late-release policies.
//
// A job reads its inputs when it starts (the module's cycle() runs then), takes the simulated
// time the task's `virtual_exec` and the module's consume_virtual_time() give it, may be
// preempted meanwhile, and publishes its outputs when it ends. With no simulated time a job
// starts and ends at its release, in policy order.

#include <atomic>
#include <cstdint>
#include <vector>

#include "chimera/exec/task.hpp"
#include "release_order.hpp"
#include "schedule_plan.hpp"

namespace chimera {

class GlobalTable;

class VirtualExecutive {
 public:
  VirtualExecutive(std::vector<Task*> tasks, const ReleaseOrder& order, SchedulePlan plan, const GlobalTable& table);

  [[nodiscard]] std::int64_t now_ns() const { return now_ns_; }
  /// Applies a signal at the current simulated time. A job in progress on that task ends first
  /// (as on the real clock, where signals are handled between cycles).
  Result<void> signal(std::size_t task, Signal signal);
  /// Runs every event before `end_ns`, then sets the time to `end_ns` (jobs in progress keep
  /// their remaining time). With `watch`, stops early at the first instant after which its value
  /// has changed (a task asked for a switch), and returns false. Real-time safe.
  bool run_until(std::int64_t end_ns, const std::atomic<std::uint32_t>* watch = nullptr);
  /// reinit() of task `task` at the current simulated time.
  Result<void> reinit(std::size_t task);
  /// A new plan (MUF's critical set after a switch), from the next dispatch on.
  void set_plan(SchedulePlan plan) { plan_ = std::move(plan); }

  /// How often the descriptor of an idle aperiodic task is polled while it has nothing to read;
  /// after a job it is polled again at once (the descriptor is level-triggered).
  static constexpr std::int64_t kPollPeriodNs = 1'000'000;

 private:
  static constexpr std::size_t kMaxRefills = 64;  // pending refills per server; more are merged

  struct Job {
    bool active = false;   // released and not ended
    bool started = false;  // begin_job ran
    std::int64_t release_ns = 0;
    std::int64_t remaining_ns = 0;   // simulated time still to run, once started
    std::int64_t exec_ns = 0;        // simulated time the job takes in all
    std::int64_t wait_until_ns = 0;  // precedence: waits for same-release producers until then
  };
  struct Server {
    std::int64_t budget_ns = 0;
    std::vector<std::pair<std::int64_t, std::int64_t>> refills;  // (time, amount), in time order
  };
  struct Slot {
    Job job;
    std::int64_t next_release_ns = -1;       // periodic: release of the next job; -1: not scheduled
    std::int64_t first_release_ns = 0;       // periodic: the first release since it turned on
    std::int64_t last_done_release_ns = -1;  // the release of the last job that ended
    std::int64_t job_start_ns = 0;
    std::uint64_t events = 0;          // aperiodic: events not served yet
    std::int64_t next_fd_poll_ns = 0;  // aperiodic, descriptor trigger: when to look at it again
    std::uint64_t seen_version = 0;    // aperiodic, update trigger: the variable's version served
    int trigger_var = -1;              // aperiodic, update trigger: the variable's index
    Server server;
  };

  [[nodiscard]] JobUrgency urgency_of(std::size_t i) const;
  [[nodiscard]] bool ready(std::size_t i) const;
  [[nodiscard]] bool blocked_by_producer(std::size_t i) const;
  void release_periodic(std::size_t i);
  void poll_triggers();
  void refill_servers();
  void dispatch();
  void step();
  void finish(std::size_t i);
  void end_open_job(std::size_t i);
  [[nodiscard]] std::int64_t next_event_after_dispatch() const;
  void advance_to(std::int64_t t);

  std::vector<Task*> tasks_;
  const ReleaseOrder& order_;
  SchedulePlan plan_;
  const GlobalTable& table_;
  std::vector<Slot> slots_;
  std::vector<int> running_;   // per CPU slot (index into plan_.cpu values via cpu_slot_): task or -1
  std::vector<int> cpu_slot_;  // per task: index into running_
  std::int64_t now_ns_ = 0;
  std::int64_t stepped_ns_ = -1;  // the last instant whose releases were dispatched
};

}  // namespace chimera
