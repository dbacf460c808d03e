#pragma once
// The flight recorder (docs/flight-recorder.md): the last few seconds of every state variable a
// task produces and of every task's timing, kept in memory allocated once, written by the tasks'
// own transfers (a bounded ring write per output and per cycle, nothing else on the real-time
// path), and dumped to a directory on request: when a task enters ERROR, on `dump`, at exit.
// Private to the control part.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "chimera/config/verify.hpp"
#include "chimera/core/history_rings.hpp"
#include "chimera/core/result.hpp"
#include "chimera/svt/global_table.hpp"
#include "exec/task_set.hpp"

namespace chimera {

class FlightRecorder {
 public:
  /// The memory the recorder may take; a longer history that would need more is shortened to fit.
  static constexpr std::size_t kMostBytes = std::size_t{256} << 20;
  /// Records a ring holds at most, whatever its rate.
  static constexpr std::uint32_t kMostRecords = 1U << 20;

  /// Where the rings live: this process's memory, or a memfd that module processes map too, so
  /// that their tasks record what they write and how they cycle (docs/processes.md).
  enum class Memory { kPrivate, kShared };

  /// Rings for `seconds` of history of every variable that a task of `resolved` produces (at its
  /// fastest producer's rate) and of every task's cycles, and every task of `tasks` writing into
  /// them. When the memory bound makes the history shorter than asked, shortened() is set and
  /// seconds() is its length. Fails only for shared memory that cannot be had. Not real-time safe.
  static Result<std::unique_ptr<FlightRecorder>> create(const ResolvedSubsystem& resolved, const GlobalTable& table,
                                                        TaskSet& tasks, double seconds, Memory memory);
  /// A module process's side: the rings the main process made shared, open here as `fd` (kept),
  /// laid out again from the same file and its seconds() (so unshortened), and the tasks of
  /// `tasks` writing into them. Refused when the layouts differ. Not real-time safe.
  static Result<std::unique_ptr<FlightRecorder>> attach(const ResolvedSubsystem& resolved, const GlobalTable& table,
                                                        TaskSet& tasks, double seconds, int fd);
  FlightRecorder(const FlightRecorder&) = delete;
  FlightRecorder& operator=(const FlightRecorder&) = delete;
  FlightRecorder(FlightRecorder&&) = delete;
  FlightRecorder& operator=(FlightRecorder&&) = delete;
  ~FlightRecorder() = default;

  /// How much history it keeps (seconds of the fastest producer), and its memory.
  [[nodiscard]] double seconds() const noexcept { return seconds_; }
  [[nodiscard]] bool shortened() const noexcept { return shortened_; }
  [[nodiscard]] std::size_t bytes() const noexcept { return rings_.bytes(); }
  /// The shared rings' memfd, for a module process to inherit; -1 when private.
  [[nodiscard]] int shared_fd() const noexcept { return rings_.fd(); }

  /// Writes what it holds into directory `dir` (made if missing; its files replaced):
  /// variables.csv (a data_logger log: t, then each element, one row per instant a variable was
  /// written, each variable's latest value at that instant), timing.csv (one row per cycle of
  /// every task), summary.txt (`why`, each task's state and last error, the window),
  /// subsystem.yaml (`subsystem_yaml`: what ran, as `save` writes it) and constants.yaml (the
  /// values of the constants the tasks produced, as a file's `constants:` map). `now_ns` is the subsystem's
  /// time. Not real-time safe; the tasks run on meanwhile.
  [[nodiscard]] Result<void> dump(const std::string& dir, const std::string& why, std::int64_t now_ns,
                                  const std::vector<std::string>& task_lines, const std::string& subsystem_yaml) const;

 private:
  struct RecordedVariable {
    VarIndex var = 0;
    std::size_t ring = 0;
  };
  // Lays the rings out; the block is made (or attached) and the tasks bound by create or attach.
  FlightRecorder(const ResolvedSubsystem& resolved, const GlobalTable& table, TaskSet& tasks, double seconds);
  void bind_tasks() noexcept;
  Result<void> write_variables(const std::string& path) const;
  Result<void> write_timing(const std::string& path) const;
  Result<void> write_constants(const std::string& path) const;

  const GlobalTable& table_;
  TaskSet& tasks_;
  HistoryRings rings_;
  std::vector<std::int32_t> ring_of_var_;    // per variable of the table, -1: not recorded
  std::vector<RecordedVariable> variables_;  // the recorded ones, in table order
  std::vector<std::int32_t> timing_ring_;    // per task
  std::vector<VarIndex> constants_;          // the out-consts of the tasks, in table order
  double seconds_ = 0;
  bool shortened_ = false;
};

}  // namespace chimera
