#pragma once
// The one command API of the subsystem interface: the shell, `chimera run`'s scripted input and
// (later) the network API hand it parsed commands and print its replies.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/control/command.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/lifecycle/state.hpp"

namespace chimera {

/// What a command produced. A refused command has ok == false, one line of text saying why,
/// and changed nothing.
struct Reply {
  bool ok = true;
  std::string text;          // zero or more lines, each ending in '\n'
  bool quit = false;         // `quit`: the caller stops the subsystem (Subsystem::stop)
  std::int64_t wait_ns = 0;  // `wait`: the caller lets the subsystem run this long (run_for)
};

/// Carries out commands on one Subsystem. Never blocks a real-time thread: it only calls the
/// Subsystem's API, which guarantees that. Not real-time safe; use from one thread at a time.
class Control {
 public:
  explicit Control(Subsystem& subsystem) : subsystem_(subsystem) {}

  /// Carries out `command` except the parts the caller owns: the waiting of `wait` and the
  /// stopping of `quit`, which it only announces in the Reply.
  Reply execute(const Command& command);
  /// parse_command() then execute(); a blank or comment line gives an empty ok Reply.
  Reply execute_line(std::string_view line);

  /// One line per event since the last call, e.g. "robot: ERROR: joint limit" ("" if none).
  std::string drain_events();

 private:
  Reply signal_tasks(Signal signal, const std::vector<std::string>& names);
  Reply get(const std::string& variable) const;
  Reply set(const std::string& variable, const std::vector<double>& values);
  // The live assembly's verbs (assembly_commands.cpp).
  Reply assemble(const Command& command);
  Reply add(const std::string& entry);
  Reply define(const std::vector<std::string>& args);
  Reply verify(const std::string& configuration) const;
  Reply remove(const std::string& task);
  Reply save(const std::vector<std::string>& args) const;
  Reply open(const std::string& file);

  Subsystem& subsystem_;
};

/// Why a configuration is not legal, as the set difference in words: "tau_r has no producer (read
/// by pid)", "theta_d has more than one producer (ik, integ)"; other rules as verification says.
std::string violation_reason(const Violation& violation);

/// One line per event, e.g. "robot: ERROR: joint limit" ("" if none): what the shell prints.
std::string event_lines(const std::vector<Event>& events);

/// The state a task must be in to accept `signal`, for messages ("OFF", "OFF, ON or ERROR").
std::string_view required_state_text(Signal signal);

}  // namespace chimera
