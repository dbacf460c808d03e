#pragma once
// The inside of a Subsystem, shared by the files that implement its parts: creation and signals
// (exec/subsystem.cpp) and dynamic reconfiguration (reconfig/switch.cpp).

#include <atomic>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "chimera/exec/subsystem.hpp"
#include "chimera/exec/task.hpp"
#include "real_executive.hpp"
#include "reconfig/request_board.hpp"
#include "release_order.hpp"
#include "schedule_plan.hpp"
#include "virtual_executive.hpp"

namespace chimera {

namespace detail {
class TableFlags final : public SubsystemFlags {
 public:
  explicit TableFlags(const GlobalTable* table) : table_(table) {}
  [[nodiscard]] bool illegal_configuration() const noexcept override { return table_->illegal_configuration(); }

 private:
  const GlobalTable* table_;
};

}  // namespace detail

struct Subsystem::Impl {
  SubsystemSpec spec;
  RunOptions options;
  Resolution resolution;
  std::string configuration;
  std::unique_ptr<GlobalTable> table;
  std::unique_ptr<detail::TableFlags> flags;
  std::vector<std::unique_ptr<Task>> tasks;
  ReleaseOrder order;
  SchedulePlan plan;
  std::unique_ptr<VirtualExecutive> virtual_exec;
  std::unique_ptr<RealExecutive> real_exec;
  std::vector<std::string> last_error;
  std::vector<Event> pending;  // collected from the tasks' rings, not yet handed to a caller
  std::mutex events_mutex;     // guards pending and last_error; never taken by a task's thread
  std::int64_t stopped_at_ns = 0;
  bool stopped = false;

  // Dynamic reconfiguration (reconfig/switch.cpp).
  std::unique_ptr<SubsystemRequestBoard> requests;
  std::vector<int> served;  // per task: the request last dealt with (-1: none)
  std::vector<SwitchRecord> history;
  // The flag is up for a switch that must create tasks. Relaxed: update_flag reads it under
  // flag_mutex, and whoever changes it calls update_flag next.
  std::atomic<bool> switching_flag{false};
  std::mutex ops_mutex;  // signals, switches and stop: from the shell or the request service
  // Real clock: carries out the switches tasks ask for, and every kWatchTickNs watches for jobs
  // still running past their deadline (exec/overrun_watch.cpp).
  std::thread service;
  std::atomic<bool> service_stop{false};

  // The overrun watch: a job stuck in cycle() is a deadline miss that end_job would count only
  // once it ends, perhaps never; the watch reports it while it lasts and, for a hard task, keeps
  // the illegal-configuration flag up, so that the robot interfaces hold still.
  static constexpr std::int64_t kWatchTickNs = 5'000'000;
  std::vector<std::int64_t> overdue_reported;  // per task: the deadline of the job last reported (the service's)
  std::atomic<int> hard_overdue{0};            // hard tasks with a job overdue now; relaxed, as switching_flag
  std::mutex flag_mutex;                       // update_flag's reading of its inputs and storing of the flag
  /// One look at every task's running job; reports the newly overdue, then updates the flag.
  void watch_overruns();

  // The steps of a switch (reconfig/switch.cpp).
  /// Creates `to_spawn` in the background, publishing nothing; kills them again if one fails.
  Result<void> create_for_switch(const std::vector<std::size_t>& to_spawn);
  /// The commit: `leaving` off and `joining` on at one cycle boundary (after a cycle of the old
  /// configuration on the virtual clock when the switch `created` tasks). Plans `target` anew.
  Result<void> commit_switch(const std::vector<std::size_t>& leaving, const std::vector<std::size_t>& joining,
                             bool created, const std::vector<std::string>& target);
  /// reinit() on every ON task outside `joining` that reads a constant of `changed`; their names.
  std::vector<std::string> reinit_readers(const std::vector<std::string>& changed,
                                          const std::vector<std::size_t>& joining);
  /// The smallest period among the periodic tasks `indices` (0: none).
  [[nodiscard]] std::int64_t shortest_period(const std::vector<std::size_t>& a,
                                             const std::vector<std::size_t>& b) const;

  /// The illegal-configuration flag: up while a switch creates tasks, while a task is in ERROR, or
  /// while a hard task's job runs past its deadline. From any thread of the interface; the one
  /// who changes an input calls it next, so the last call sees the last inputs.
  void update_flag() {
    std::lock_guard<std::mutex> lock(flag_mutex);
    // Relaxed: both are read under flag_mutex, after their writer's change (see above).
    bool raise = switching_flag.load(std::memory_order_relaxed) || hard_overdue.load(std::memory_order_relaxed) > 0;
    for (const auto& t : tasks) raise = raise || t->state() == TaskState::kError;
    // Stored only when it changes: every task polls the flag's line.
    if (table->illegal_configuration() != raise) table->set_illegal_configuration(raise);
  }

  /// Moves every task's real-time events into `pending` and notes the last failure of each.
  void collect_events() {
    std::lock_guard<std::mutex> lock(events_mutex);
    RtEvent e;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      while (tasks[i]->events().pop(e)) {
        pending.push_back(Event{e.time_ns, tasks[i]->name(), e.text.data()});
        if (std::strstr(e.text.data(), "ERROR") != nullptr || std::strstr(e.text.data(), "failed") != nullptr)
          last_error[i] = e.text.data();
      }
    }
  }

  [[nodiscard]] std::int64_t now() const {
    if (stopped) return stopped_at_ns;
    return virtual_exec ? virtual_exec->now_ns() : real_exec->now_ns();
  }
  Result<void> signal(std::size_t i, Signal s) const {  // const: the executives are owned, not members' state
    return virtual_exec ? virtual_exec->signal(i, s) : real_exec->signal(i, s);
  }
  std::optional<std::size_t> index_of(std::string_view name) const {
    for (std::size_t i = 0; i < tasks.size(); ++i)
      if (tasks[i]->name() == name) return i;
    return std::nullopt;
  }
};

}  // namespace chimera
