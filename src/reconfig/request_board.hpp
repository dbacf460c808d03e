#pragma once
// Where modules' switch requests wait for the subsystem interface: one slot per task holding the
// configuration it asks for, and a doorbell rung with every new request (the real clock's service
// thread sleeps on it, the virtual executive watches it). Exported to the parts above.

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/module/module.hpp"
#include "exec/doorbell.hpp"

namespace chimera {

class SubsystemRequestBoard final : public RequestBoard {
 public:
  SubsystemRequestBoard(std::vector<std::string> configurations, std::size_t tasks);

  [[nodiscard]] int configuration_index(std::string_view name) const override;
  /// Real-time safe: one exchange, and a doorbell ring only when the request is new.
  void post(int task, int configuration) noexcept override;

  /// The configuration task `task` asks for, or -1. Not real-time safe.
  [[nodiscard]] int asked(std::size_t task) const noexcept;
  /// Forgets every request (after a switch: asking again is then new). Not real-time safe.
  void clear() noexcept;
  [[nodiscard]] const std::string& configuration_name(int index) const {
    return configurations_[static_cast<std::size_t>(index)];
  }
  /// Rings with every new request.
  [[nodiscard]] Doorbell& bell() noexcept { return bell_; }

 private:
  std::vector<std::string> configurations_;
  std::vector<std::atomic<int>> slots_;  // per task: the configuration asked for, -1: none
  Doorbell bell_;
};

}  // namespace chimera
