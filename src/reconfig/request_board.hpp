#pragma once
// Where modules' switch requests wait for the subsystem interface: one slot per task holding the
// configuration it asks for, and a word that changes with every new request (a futex for the
// real clock's service thread, a watch for the virtual executive).

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/module/module.hpp"

namespace chimera {

class SubsystemRequestBoard final : public RequestBoard {
 public:
  SubsystemRequestBoard(std::vector<std::string> configurations, std::size_t tasks);

  [[nodiscard]] int configuration_index(std::string_view name) const override;
  /// Real-time safe: one exchange, and a futex wake only when the request is new.
  void post(int task, int configuration) noexcept override;

  /// The configuration task `task` asks for, or -1. Not real-time safe.
  [[nodiscard]] int asked(std::size_t task) const noexcept;
  /// Forgets every request (after a switch: asking again is then new). Not real-time safe.
  void clear() noexcept;
  [[nodiscard]] const std::string& configuration_name(int index) const {
    return configurations_[static_cast<std::size_t>(index)];
  }
  /// Changes with every new request.
  [[nodiscard]] const std::atomic<std::uint32_t>& changes() const noexcept { return changes_; }
  /// Wakes whoever waits on changes() without a request (to stop the service thread).
  void wake() noexcept;

 private:
  std::vector<std::string> configurations_;
  std::vector<std::atomic<int>> slots_;  // per task: the configuration asked for, -1: none
  alignas(64) std::atomic<std::uint32_t> changes_{0};
};

}  // namespace chimera
