#include "task_set.hpp"

namespace chimera {

TaskSet::TaskSet(const ResolvedSubsystem& subsystem, GlobalTable& table, RequestBoard* requests,
                 const std::vector<TaskShared*>& shared)
    : flags_(table) {
  for (const auto& resolved : subsystem.tasks) {
    const std::size_t i = tasks_.size();
    tasks_.push_back(std::make_unique<Task>(resolved, table, flags_, i < shared.size() ? shared[i] : nullptr));
    tasks_.back()->set_request_board(requests, static_cast<int>(tasks_.size() - 1));
  }
}

std::optional<std::size_t> TaskSet::index_of(std::string_view name) const {
  for (std::size_t i = 0; i < tasks_.size(); ++i)
    if (tasks_[i]->name() == name) return i;
  return std::nullopt;
}

std::vector<Task*> TaskSet::pointers() const {
  std::vector<Task*> out;
  out.reserve(tasks_.size());
  for (const auto& t : tasks_) out.push_back(t.get());
  return out;
}

bool TaskSet::hard_task_failed() const noexcept {
  for (const auto& t : tasks_)
    if (t->hard() && t->ever_in_error()) return true;
  return false;
}

}  // namespace chimera
