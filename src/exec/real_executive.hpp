#pragma once
// The real clock: one thread per task, from spawn to kill, with SCHED_FIFO priorities by rate
// and CPU affinity where the system allows. Periodic releases are at absolute times
// epoch + k * period (no drift). Signals travel through a one-slot mailbox per task: the
// control thread posts and waits; the task's thread carries the signal out between cycles and
// never waits for the control thread.

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/exec/task.hpp"
#include "release_order.hpp"

namespace chimera {

class RealExecutive {
 public:
  RealExecutive(const std::vector<Task*>& tasks, const ReleaseOrder& order, const SubsystemSpec& spec, bool realtime);
  ~RealExecutive();
  RealExecutive(const RealExecutive&) = delete;
  RealExecutive& operator=(const RealExecutive&) = delete;

  /// Time since the executive's epoch on CLOCK_MONOTONIC.
  [[nodiscard]] std::int64_t now_ns() const;
  /// Carries out a signal on the task's own thread (started by spawn, ended by kill) and
  /// waits for it. Not real-time safe; never blocks a task's thread.
  Result<void> signal(std::size_t index, Signal sig);

  struct Worker;

 private:
  std::vector<std::unique_ptr<Worker>> workers_;
  std::int64_t epoch_ns_ = 0;
  bool realtime_ = false;
  std::mutex control_mutex_;  // one control request at a time; never taken by a task's thread
};

/// Asks for mlockall and reports, once per process, when real-time facilities are refused.
void prepare_realtime_process(bool realtime);

}  // namespace chimera
