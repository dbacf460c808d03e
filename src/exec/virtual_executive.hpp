#pragma once
// The virtual clock: the subsystem's schedule simulated on simulated time by the calling thread,
// deterministically and as fast as the machine allows. It is a discrete-event simulation of the
// real executive: each task on its CPU, jobs released at whole multiples of the period (or by
// their trigger, for aperiodic tasks), preemptive, in the order the file's policy gives
// (urgency.hpp), following the same release policy (release_policy.hpp: the grid, late
// releases, the same-rate rule; sporadic_server.hpp).
//
// A job reads its inputs when it starts (the module's cycle() runs then), takes the simulated
// time the task's `virtual_exec` and the module's consume_virtual_time() give it, may be
// preempted meanwhile, and publishes its outputs when it ends. With no simulated time a job
// starts and ends at its release, in policy order.

#include <cstdint>
#include <vector>

#include "chimera/analysis/release_order.hpp"
#include "executive.hpp"
#include "schedule_plan.hpp"
#include "sporadic_server.hpp"

namespace chimera {

class VirtualExecutive final : public Executive {
 public:
  explicit VirtualExecutive(ExecutiveSetup setup);
  ~VirtualExecutive() override;
  VirtualExecutive(const VirtualExecutive&) = delete;
  VirtualExecutive& operator=(const VirtualExecutive&) = delete;
  VirtualExecutive(VirtualExecutive&&) = delete;
  VirtualExecutive& operator=(VirtualExecutive&&) = delete;

  // Executive.
  [[nodiscard]] ClockKind clock() const noexcept override { return ClockKind::kVirtual; }
  [[nodiscard]] std::int64_t now_ns() const override { return now_ns_; }
  [[nodiscard]] int cpu_of(std::size_t task) const override { return cpus_[task]; }
  /// At the current simulated time. A job in progress on that task ends first (as on the real
  /// clock, where signals are handled between cycles).
  Result<void> signal(std::size_t task, Signal signal) override;
  /// The simulated clock does not move while they turn on: one after the other is together.
  Result<void> turn_on_together(const std::vector<std::size_t>& tasks) override;
  CommitOutcome commit_switch(const SwitchCommit& commit) override;
  Result<void> reinit(std::size_t task) override;
  void run_for(std::int64_t ns) override;
  void serve(ServiceHooks hooks) override { hooks_ = std::move(hooks); }
  void stop_serving() override { hooks_ = ServiceHooks{}; }
  /// The simulation sees a new version of a trigger variable by itself.
  void variable_written(VarIndex /*v*/) override {}
  void shutdown() override;
  // Its tasks run on the caller's thread: a method stuck there holds the caller, and nothing is
  // left behind that could be waited for.
  void begin_stop() override {}
  [[nodiscard]] std::vector<std::string> left_behind() const override { return {}; }
  void watch_writes(VarIndex /*v*/, WriteWatch* /*watch*/) override {}

  /// Runs every event before `end_ns`, then sets the time to `end_ns` (jobs in progress keep
  /// their remaining time). With `watch`, stops early at the first instant after which it has
  /// rung (a task asked for a switch), and returns false. Real-time safe.
  bool run_until(std::int64_t end_ns, const Doorbell* watch = nullptr);

  /// How often the descriptor of an idle aperiodic task is polled while it has nothing to read;
  /// after a job it is polled again at once (the descriptor is level-triggered).
  static constexpr std::int64_t kPollPeriodNs = 1'000'000;

 private:
  struct Job {
    bool active = false;   // released and not ended
    bool started = false;  // begin_job ran
    std::int64_t release_ns = 0;
    std::int64_t remaining_ns = 0;   // simulated time still to run, once started
    std::int64_t exec_ns = 0;        // simulated time the job takes in all
    std::int64_t wait_until_ns = 0;  // the same-rate rule: waits for same-release producers until then
  };
  struct Slot {
    Job job;
    std::int64_t next_release_ns = -1;       // periodic: release of the next job; -1: not scheduled
    std::int64_t last_done_release_ns = -1;  // the release of the last job that ended
    std::int64_t job_start_ns = 0;
    std::uint64_t events = 0;          // aperiodic: events not served yet
    std::int64_t next_fd_poll_ns = 0;  // aperiodic, descriptor trigger: when to look at it again
    std::uint64_t seen_version = 0;    // aperiodic, update trigger: the variable's version served
    SporadicServer server;
  };

  [[nodiscard]] JobUrgency urgency_of(std::size_t i) const;
  [[nodiscard]] bool ready(std::size_t i) const;
  [[nodiscard]] bool blocked_by_producer(std::size_t i) const;
  [[nodiscard]] bool starts_without_a_producer(std::size_t i) const;
  void drop_if_too_late(std::size_t i);
  void release_periodic(std::size_t i);
  void poll_triggers();
  void refill_servers();
  void start_job(std::size_t i);
  void dispatch();
  void step();
  void finish(std::size_t i);
  void end_open_job(std::size_t i);
  [[nodiscard]] std::int64_t next_event_after_dispatch() const;
  void advance_to(std::int64_t t);

  const ResolvedSubsystem& subsystem_;
  const GlobalTable& table_;
  std::vector<Task*> tasks_;
  analysis::ReleaseOrder order_;
  SchedulePlan plan_;
  const std::vector<int> cpus_;  // plan_.cpu as it was made: a switch never moves a task, so any thread may read it
  ServiceHooks hooks_;
  std::vector<Slot> slots_;
  std::vector<int> running_;   // per CPU slot (index into plan_.cpu values via cpu_slot_): task or -1
  std::vector<int> cpu_slot_;  // per task: index into running_
  std::int64_t now_ns_ = 0;
  std::int64_t stepped_ns_ = -1;  // the last instant whose releases were dispatched
  bool stopped_ = false;
};

}  // namespace chimera
