#pragma once
// EDF and MUF on the real clock: one dispatcher thread per CPU, above every task's priority,
// that turns the policy's order of the jobs on its CPU into SCHED_FIFO priorities. A task's
// thread wakes for its release in the "releasing" band (just below the dispatcher), publishes
// its job (release, absolute deadline) and pokes the dispatcher, which preempts it at once on
// that CPU, ranks every active job by urgency.hpp's order and sets the priorities that changed.
// When the poke returns, the kernel runs the most urgent job. Priorities change only at releases:
// the order of the other jobs does not change when one ends. docs/scheduling.md says why this
// design and not SCHED_DEADLINE.

#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "real_worker.hpp"
#include "schedule_plan.hpp"

namespace chimera {

class PriorityDispatcher {
 public:
  static constexpr int kPriority = 90;           // the dispatcher itself
  static constexpr int kReleasingPriority = 89;  // a task between waking and being ranked
  static constexpr int kTopJobPriority = 88;     // the most urgent job; then one less each
  static constexpr int kLowestJobPriority = 2;   // 1 is background work

  PriorityDispatcher(int cpu, SchedulerKind policy, std::vector<Worker*> workers,
                     const std::vector<TaskUrgency>& urgency);
  ~PriorityDispatcher();
  PriorityDispatcher(const PriorityDispatcher&) = delete;
  PriorityDispatcher& operator=(const PriorityDispatcher&) = delete;

  /// Starts the thread (SCHED_FIFO kPriority on `cpu` when `realtime`; without, it only keeps
  /// the books: ordinary threads have no priorities to set). Not real-time safe.
  void start(bool realtime);
  /// Asks for the jobs to be ranked again now. Real-time safe (one futex wake).
  void poke() noexcept;
  /// New urgency data for its tasks (MUF's critical set after a switch), in the order of the
  /// workers given at construction; returns once the dispatcher ranks by it. Not real-time safe;
  /// one caller at a time.
  void set_urgency(const std::vector<TaskUrgency>& urgency);
  [[nodiscard]] int cpu() const { return cpu_; }
  [[nodiscard]] const std::vector<Worker*>& workers() const { return workers_; }

  /// The priorities that `policy` gives jobs `jobs` of tasks `urgency` (parallel arrays; only
  /// entries with active[i] count): kTopJobPriority for the most urgent, one less each after,
  /// never below kLowestJobPriority; background tasks get 1; inactive ones 0. Exposed for tests.
  static void rank(SchedulerKind policy, const std::vector<TaskUrgency>& urgency, const std::vector<JobUrgency>& jobs,
                   const std::vector<bool>& active, std::vector<int>& order_scratch, std::vector<int>& priorities);

 private:
  void main();
  void rerank();

  int cpu_;
  SchedulerKind policy_;
  std::vector<Worker*> workers_;
  // Two sets of urgency data: the dispatcher ranks by urgency_[active_set_]; set_urgency() fills
  // the other, flips the index and waits until the dispatcher has taken it (taken_ == flips_).
  std::array<std::vector<TaskUrgency>, 2> urgency_;
  alignas(64) std::atomic<std::uint32_t> flips_{0};
  std::atomic<std::uint32_t> taken_{0};
  // Scratch, sized once: ranking allocates nothing.
  std::vector<JobUrgency> jobs_;
  std::vector<bool> active_;
  std::vector<int> order_;
  std::vector<int> priorities_;
  pthread_t thread_{};
  bool started_ = false;
  bool realtime_ = false;
  alignas(64) std::atomic<std::uint32_t> bell_{0};
  std::atomic<bool> stopping_{false};
};

}  // namespace chimera
