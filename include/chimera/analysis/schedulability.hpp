#pragma once
// Schedulability of one CPU's tasks, and of a whole configuration, under the file's scheduler:
// rm and dm by exact response-time analysis, edf by the utilisation or processor-demand test,
// muf by the feasibility of its critical set. docs/scheduling.md explains each with numbers.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/analysis/processor_demand.hpp"
#include "chimera/analysis/task_model.hpp"
#include "chimera/config/subsystem.hpp"

namespace chimera::analysis {

enum class Verdict {
  kMeets,        // every job meets its deadline
  kCanMiss,      // some job can miss, or nothing bounds the task (the reason says which)
  kNoGuarantee,  // MUF: not in the critical set, so by design nothing is promised
  kBackground,   // aperiodic without a server: runs when nothing else does, no guarantee
};

std::string_view verdict_name(Verdict verdict);

/// Why an EDF test failed, in one line ("overloaded: U = 1.100 > 1"); "" if it passed.
std::string edf_failure_reason(const EdfTest& test);

/// Which test decided a CPU.
enum class CpuTest {
  kNone,                // no task with a period on the CPU
  kResponseTime,        // rm, dm
  kEdfUtilisation,      // edf, every D >= T
  kEdfProcessorDemand,  // edf, some D < T
  kMufCriticalSet,      // muf: the critical set by EDF's test
};

struct TaskResult {
  std::size_t index = 0;  // into the tasks given
  /// The analysed C (with the overhead, for a server its budget plus one job), T and D;
  /// nullopt for a background task or an unknown C.
  std::optional<Demand> demand;
  Verdict verdict = Verdict::kCanMiss;
  /// rm, dm: the worst-case response time (when the reason says "at least", a lower bound past the
  /// deadline). edf, muf: the deadline, an upper bound (response_is_bound). 0: none.
  std::int64_t response_ns = 0;
  bool response_is_bound = false;
  /// rm, dm: response_ns is the latest completion found before the analysis gave up, already
  /// past the deadline, so the true worst case is at least that (the reason says "at least").
  bool response_is_lower_bound = false;
  bool critical = false;  // muf: in the critical set the run uses
  /// How long after its release the task may wait for its same-rate producers on other CPUs
  /// (analyse_configuration(); 0 on one CPU). Its response time includes the wait.
  std::int64_t release_jitter_ns = 0;
  std::string reason;  // one line; empty when the task meets its deadline by the CPU's test
};

struct CpuResult {
  int cpu = -1;
  SchedulerKind scheduler = SchedulerKind::kRm;
  /// In the order the scheduler favours them: priority (rm, dm), deadline (edf), critical set
  /// first in admission order (muf); background tasks last.
  std::vector<TaskResult> tasks;
  int periodic = 0;                  // tasks with a period (servers included): the bound's n
  bool utilisation_complete = true;  // false: some C is unknown and `utilisation` leaves it out
  double utilisation = 0;            // sum C/T of the periodic tasks, overhead included
  double ll_bound = 1;               // Liu and Layland for `periodic` tasks
  bool implicit_deadlines = true;    // every D == T (where the bound applies, under rm)
  CpuTest test = CpuTest::kNone;
  /// edf: the test of all tasks; muf: of the critical set (the run's, analysis/muf.hpp) with
  /// analysis' C; a critical task of unknown C is left out of it (and cannot be bounded).
  EdfTest edf;
  /// edf, muf: the longest busy period of those tasks (longest_busy_period()), 0 if none: a job
  /// that becomes ready ends within it, a tighter bound than D on how long a consumer on another
  /// CPU waits for it. (rm, dm have exact response times.)
  std::int64_t busy_period_ns = 0;
  /// muf: a hard task is outside the critical set (it does not fit with the C a run knows).
  bool hard_left_out = false;
  /// Every task meets its deadline, but for muf's non-critical tasks and background tasks.
  bool feasible = true;
};

/// Analyses the tasks of one CPU (their `cpu` field is not looked at). Under muf the critical set
/// is the run's (runtime_critical_set(): the C a run knows, its overhead) when the models come
/// from a file (run_wcet_ns set), else muf_critical_set() with `options`; either way it is then
/// checked with the models' C and `options`. Not real-time safe.
[[nodiscard]] CpuResult analyse_cpu(std::span<const TaskModel> tasks, SchedulerKind scheduler,
                                    const AnalysisOptions& options = {});

struct ConfigurationResult {
  std::vector<int> cpu_of;      // per task given: the CPU it runs on
  std::vector<CpuResult> cpus;  // one per CPU, by CPU number; TaskResult::index counts the tasks given
  bool feasible = true;
};

/// Analyses every CPU of `cpus` (and any other that `cpu_of` names) with the tasks `cpu_of` puts
/// there. A task whose same-rate producers (TaskModel::same_rate_producers) run on another CPU
/// waits for them at each release (the same-rate rule): their response time becomes its release
/// jitter, found by iterating to a fixed point (holistic analysis); a producer without a bound
/// leaves its consumer without one. Not real-time safe.
[[nodiscard]] ConfigurationResult analyse_configuration(std::span<const TaskModel> tasks, std::span<const int> cpu_of,
                                                        std::span<const int> cpus, SchedulerKind scheduler,
                                                        const AnalysisOptions& options = {});

}  // namespace chimera::analysis
