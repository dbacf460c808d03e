#pragma once
// The one Control of a running subsystem, shared by everything that drives it: the shell on
// standard input and the network API's request threads. Control is for one thread at a time;
// the gate carries out each command whole before the next starts, in arrival order of the lock.

#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "chimera/control/control.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/net/event_feed.hpp"

namespace chimera::net {

class ControlGate {
 public:
  /// How long one step of run_for() holds the gate on the virtual clock: commands from other
  /// drivers wait at most about this much simulated time.
  static constexpr std::int64_t kStepNs = 50'000'000;

  explicit ControlGate(Subsystem& subsystem) : subsystem_(subsystem), control_(subsystem) {}

  /// Control::execute() and execute_line(), one caller at a time; then the feed sees what the
  /// command changed. Not real-time safe.
  Reply execute(const Command& command);
  Reply execute_line(std::string_view line);
  /// Control::drain_events(), one caller at a time: the events go into the feed too, with the
  /// state changes since the last look. Whoever drives the subsystem calls it every few tens of
  /// milliseconds (the run's loop does, every 50 ms), so the feed is never further behind.
  std::string drain_events();

  /// What happened, for the streams (chimera/net/event_feed.hpp). Any thread.
  [[nodiscard]] const EventFeed& feed() const { return feed_; }
  /// The subsystem's figures, without the gate (snapshot() is safe from any thread).
  [[nodiscard]] std::vector<TaskSnapshot> snapshot() const { return subsystem_.snapshot(); }
  [[nodiscard]] std::vector<std::pair<std::string, TaskState>> states() const { return subsystem_.states(); }

  /// Lets the subsystem run for `ns`. On the virtual clock the caller's thread runs the tasks,
  /// so each step of at most kStepNs holds the gate (other drivers' commands come in between);
  /// on the real clock it is a sleep and holds nothing.
  void run_for(std::int64_t ns);

  /// Runs `f(control, subsystem)` holding the gate: a command and what the caller reads of the
  /// subsystem right after it, with no other driver's command in between. The feed then sees
  /// what it changed.
  template <class F>
  auto exclusive(F&& f) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto result = std::forward<F>(f)(control_, subsystem_);
    feed_.observe(subsystem_);
    return result;
  }

  /// The current value of a variable, without the gate: Subsystem::get() is safe from any
  /// thread and reads the table as any reader does, so a stream never waits for a command.
  [[nodiscard]] Result<std::vector<double>> sample(std::string_view variable) const { return subsystem_.get(variable); }

  /// The shortest period of the periodic tasks that write any of `variables` (their out-var
  /// ports, after renames, in any configuration): the fastest any of them changes, and so the
  /// fastest a stream samples them. 0 when one of them has no periodic writer (an aperiodic task,
  /// the operator's `set`, a DDS import): how often it changes is not known. Takes the gate.
  [[nodiscard]] std::int64_t fastest_writer_period_ns(const std::vector<std::string>& variables);

  /// The subsystem's clock; fixed at creation, so no lock.
  [[nodiscard]] ClockKind clock() const { return subsystem_.clock(); }

 private:
  Subsystem& subsystem_;
  std::mutex mutex_;  // held for each command; never by a task's thread
  Control control_;
  EventFeed feed_;  // written under mutex_
};

}  // namespace chimera::net
