#pragma once
// Dynamic reconfiguration (paper 3.4; docs/reconfiguration.md): the switch state of a running
// subsystem (the configuration on, the switches done, the modules' requests) and the switch
// itself, in the two phases STYLE asks for: prepare and verify off the real-time path, where
// allocation and failure are allowed (verify, plan, create the missing tasks while the current
// configuration runs on, the illegal-configuration flag held meanwhile); then commit at one cycle
// boundary, which the executive carries out. It talks to the tasks only through the Executive.
//
// Not thread-safe: the subsystem interface calls it under its own lock. Exported to control.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/config/verify.hpp"
#include "chimera/core/result.hpp"
#include "chimera/reconfig/switch_record.hpp"
#include "chimera/svt/global_table.hpp"
#include "exec/event_log.hpp"
#include "exec/executive.hpp"
#include "exec/task_set.hpp"
#include "request_board.hpp"

namespace chimera {

class Reconfiguration {
 public:
  /// `start`: the configuration that is on at first. Everything referred to outlives this.
  Reconfiguration(const ResolvedSubsystem& subsystem, std::string start, SubsystemRequestBoard& requests,
                  TaskSet& tasks, Executive& executive, GlobalTable& table, EventLog& events);

  /// The switch to configuration `name` (Subsystem::switch_to says what it does). `cause` is
  /// logged; `requested_ns` is when it was asked for. Not real-time safe.
  Result<SwitchRecord> switch_to(std::string_view name, std::string_view cause, std::int64_t requested_ns);
  /// Carries out (or refuses, with an event) the switches tasks asked for since the last call.
  void serve_requests();

  [[nodiscard]] const std::string& configuration() const noexcept { return configuration_; }
  [[nodiscard]] const std::vector<SwitchRecord>& history() const noexcept { return history_; }
  /// The switches of an earlier runtime of the same subsystem (rebuilt by the live assembly),
  /// kept before this one's own. Not real-time safe.
  void carry_history(std::vector<SwitchRecord> earlier) { history_ = std::move(earlier); }

 private:
  /// Creates `to_spawn` in the background, publishing nothing; kills them again if one fails.
  Result<void> create_for_switch(const std::vector<std::size_t>& to_spawn);
  /// reinit() on every ON task outside `joining` that reads a constant of `changed`; their names.
  std::vector<std::string> reinit_readers(const std::vector<std::string>& changed,
                                          const std::vector<std::size_t>& joining);
  [[nodiscard]] std::vector<std::string> names_of(const std::vector<std::size_t>& indices) const;

  const ResolvedSubsystem& subsystem_;
  SubsystemRequestBoard& requests_;
  TaskSet& tasks_;
  Executive& executive_;
  GlobalTable& table_;
  EventLog& events_;
  std::string configuration_;
  std::vector<SwitchRecord> history_;
  std::vector<int> served_;  // per task: the request last dealt with (-1: none)
};

}  // namespace chimera
