#pragma once
// Where modules' switch requests wait for the subsystem interface: one slot per task holding the
// configuration it asks for, and a doorbell rung with every new request (the real clock's service
// thread sleeps on it, the virtual executive watches it). With module processes the slots and the
// bell are those of the task block, so that the same board, made in a module process over the
// same block, carries its tasks' requests to the main process. Exported to the parts above.

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/module/module.hpp"
#include "exec/doorbell.hpp"
#include "exec/task_block.hpp"

namespace chimera {

class SubsystemRequestBoard final : public RequestBoard {
 public:
  /// Slots and bell of its own.
  SubsystemRequestBoard(std::vector<std::string> configurations, std::size_t tasks);
  /// The slots and bell of `block` (which outlives the board), one slot per task of the block.
  SubsystemRequestBoard(std::vector<std::string> configurations, const TaskBlock& block);

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
  [[nodiscard]] Doorbell& bell() noexcept { return *bell_; }

 private:
  std::vector<std::string> configurations_;
  std::vector<std::atomic<int>> own_slots_;  // without a task block
  std::vector<std::atomic<int>*> slots_;     // per task: the configuration asked for, -1: none
  Doorbell own_bell_;
  Doorbell* bell_ = &own_bell_;
};

}  // namespace chimera
