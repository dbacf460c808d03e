#include "request_board.hpp"

namespace chimera {

SubsystemRequestBoard::SubsystemRequestBoard(std::vector<std::string> configurations, std::size_t tasks)
    : configurations_(std::move(configurations)), own_slots_(tasks) {
  for (auto& slot : own_slots_) slots_.push_back(&slot);
  clear();
}

SubsystemRequestBoard::SubsystemRequestBoard(std::vector<std::string> configurations, const TaskBlock& block)
    : configurations_(std::move(configurations)), bell_(&block.requests_bell()) {
  for (std::size_t i = 0; i < block.tasks(); ++i) slots_.push_back(&block.slot(i)->switch_request);
  // Not cleared: a module process's board is made while the main process's may hold requests.
}

int SubsystemRequestBoard::configuration_index(std::string_view name) const {
  for (std::size_t i = 0; i < configurations_.size(); ++i)
    if (configurations_[i] == name) return static_cast<int>(i);
  return -1;
}

void SubsystemRequestBoard::post(int task, int configuration) noexcept {
  if (task < 0 || static_cast<std::size_t>(task) >= slots_.size()) return;
  // acq_rel: what the task did before asking is seen by whoever serves the request. Asking again
  // for the same thing costs one exchange and no system call.
  if (slots_[static_cast<std::size_t>(task)]->exchange(configuration, std::memory_order_acq_rel) == configuration)
    return;
  bell_->ring();
}

int SubsystemRequestBoard::asked(std::size_t task) const noexcept {
  return slots_[task]->load(std::memory_order_acquire);  // acquire: pairs with post()
}

void SubsystemRequestBoard::clear() noexcept {
  for (auto* slot : slots_) slot->store(-1, std::memory_order_relaxed);  // only hints until the next post
}

}  // namespace chimera
