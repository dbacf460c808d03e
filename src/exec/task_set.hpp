#pragma once
// Every task of a subsystem's file, made once when the subsystem is created (NOT-CREATED until
// spawned), in file order: the index of a task here is its index everywhere (the executives, the
// plans, the reconfiguration). Exported to the parts above. Not real-time safe.

#include <cstddef>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "chimera/config/verify.hpp"
#include "chimera/module/module.hpp"
#include "chimera/svt/global_table.hpp"
#include "task.hpp"

namespace chimera {

class TaskSet {
 public:
  /// One Task per task of `subsystem`, on `table`; a module's switch requests go to `requests`
  /// (may be null). `shared[i]`, where given and not null, is where task i keeps what other
  /// processes see of it (task_shared.hpp).
  TaskSet(const ResolvedSubsystem& subsystem, GlobalTable& table, RequestBoard* requests,
          const std::vector<TaskShared*>& shared = {});

  [[nodiscard]] std::size_t size() const noexcept { return tasks_.size(); }
  [[nodiscard]] Task& operator[](std::size_t i) noexcept { return *tasks_[i]; }
  [[nodiscard]] const Task& operator[](std::size_t i) const noexcept { return *tasks_[i]; }
  [[nodiscard]] std::optional<std::size_t> index_of(std::string_view name) const;
  /// The tasks, for an executive (which keeps the pointers; the set outlives it).
  [[nodiscard]] std::vector<Task*> pointers() const;
  /// Whether a hard task has entered ERROR at any time.
  [[nodiscard]] bool hard_task_failed() const noexcept;

 private:
  // The illegal-configuration flag as modules see it: the table's header word.
  class TableFlags final : public SubsystemFlags {
   public:
    explicit TableFlags(const GlobalTable& table) : table_(table) {}
    [[nodiscard]] bool illegal_configuration() const noexcept override { return table_.illegal_configuration(); }

   private:
    const GlobalTable& table_;
  };

  TableFlags flags_;
  std::vector<std::unique_ptr<Task>> tasks_;
};

}  // namespace chimera
