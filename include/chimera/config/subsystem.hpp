#pragma once
// The subsystem model: plain structs that the YAML loader fills (contract section 1).

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "chimera/module/params.hpp"
#include "chimera/svt/elem_type.hpp"

namespace chimera {

enum class SchedulerKind { kRm, kDm, kEdf, kMuf };
enum class Criticality { kHard, kSoft };
/// What a periodic task does with releases that passed while a cycle ran late: run each of them
/// late, one after another (the grid holds, each counts as missed if it ends late), or skip
/// them and go on at the next release still ahead (each skipped release counts as missed).
enum class LatePolicy { kRun, kSkip };

std::string_view scheduler_name(SchedulerKind s);
std::string_view criticality_name(Criticality c);
std::string_view late_policy_name(LatePolicy p);

/// A sporadic server for an aperiodic task: at most `budget_ns` of execution per `period_ns`.
struct ServerSpec {
  std::int64_t budget_ns = 0;
  std::int64_t period_ns = 0;
};

/// Where something was written: for messages of the form "file:line: key: problem".
struct SourceLoc {
  std::string file;
  int line = 0;  // 1-based; 0 when unknown
};

/// The process name of the `chimera run` process itself (docs/processes.md).
inline constexpr std::string_view kMainProcess = "main";

struct TaskSpec {
  std::string name;                       // instance name, unique in the file
  std::string module;                     // module type in the registry
  std::optional<std::int64_t> period_ns;  // absent: aperiodic
  std::int64_t deadline_ns = 0;           // defaults to the period (the server's period); 0: none
  Criticality criticality = Criticality::kHard;
  std::optional<std::int64_t> wcet_ns;
  std::optional<int> cpu;
  int priority = 0;                    // user priority, MUF's third level: higher is more urgent
  LatePolicy late = LatePolicy::kRun;  // default: run for hard tasks, skip for soft ones
  std::int64_t virtual_exec_ns = 0;    // simulated execution time of a cycle on the virtual clock
  std::optional<ServerSpec> server;    // aperiodic tasks only
  Params params;
  std::map<std::string, std::string> rename;  // port name -> variable name
  /// The OS process its module runs in (docs/processes.md): kMainProcess, the chimera run
  /// process itself, unless the file names a module process.
  std::string process{kMainProcess};
  SourceLoc loc;
  std::map<std::string, int> param_lines;  // the line of each parameter the file gives

  /// Where parameter `param` is written: its line, or the task's if the file leaves it default.
  [[nodiscard]] SourceLoc loc_of_param(const std::string& param) const {
    auto it = param_lines.find(param);
    return it == param_lines.end() ? loc : SourceLoc{loc.file, it->second};
  }

  /// The variable that port `port` is bound to after renaming.
  [[nodiscard]] std::string variable_of(const std::string& port) const {
    auto it = rename.find(port);
    return it == rename.end() ? port : it->second;
  }
};

struct ConfigurationSpec {
  std::string name;
  std::vector<std::string> tasks;
  SourceLoc loc;
};

/// A switch that a task may ask for while the subsystem runs (paper 3.4: a signal that a dynamic
/// reconfiguration is required), e.g. a singularity monitor asking for damped least squares.
struct SwitchRequestSpec {
  std::string from;  // the configuration that must be on; "" for any
  std::string to;    // the configuration asked for
  std::string by;    // the task that may ask; "" for any
  SourceLoc loc;
};

/// DDS reliability of an import's reader: reliable (the default) repairs lost samples; best
/// effort takes what arrives, for high-rate variables where only the newest value matters.
enum class DdsReliability { kReliable, kBestEffort };
/// DDS durability of an import's reader: volatile (the default) sees only samples written after it
/// matched; transient local also gets the last sample a writer wrote before.
enum class DdsDurability { kVolatile, kTransientLocal };

std::string_view reliability_name(DdsReliability r);
std::string_view durability_name(DdsDurability d);

/// A state variable published to other subsystems (top-level `exports:`).
struct ExportSpec {
  std::string variable;
  SourceLoc loc;
};

/// A state variable read from another subsystem (top-level `imports:`). For verification it is
/// produced, with this shape, by the subsystem that exports it.
struct ImportSpec {
  std::string variable;
  ElemType type = ElemType::kF64;  // the wire format (Float64MultiArray) carries f64 only
  std::uint32_t count = 0;
  std::int64_t max_age_ns = 0;  // not written within this: stale
  DdsReliability reliability = DdsReliability::kReliable;
  DdsDurability durability = DdsDurability::kVolatile;
  SourceLoc loc;
};

/// Where exports and imports meet other subsystems (top-level `dds:`). The default partition
/// "" is DDS's default one, where ROS 2 nodes publish and subscribe.
struct DdsSpec {
  std::uint32_t domain = 0;
  std::string partition;
  SourceLoc loc;
};

struct SubsystemSpec {
  std::string name;
  std::string file;
  SchedulerKind scheduler = SchedulerKind::kRm;
  std::vector<int> cpus;  // empty: all
  std::vector<std::string> plugins;
  std::vector<std::pair<std::string, std::vector<double>>> constants;  // in file order
  std::vector<TaskSpec> tasks;
  std::vector<ConfigurationSpec> configurations;
  std::string start;  // a configuration name; the loader fills in the first when absent
  std::vector<SwitchRequestSpec> requests;
  std::string default_process{kMainProcess};  // top-level `process:`, the default of tasks without one

  /// Whether some task runs in a module process (a process other than main).
  [[nodiscard]] bool uses_module_processes() const {
    return std::ranges::any_of(tasks, [](const auto& t) { return t.process != kMainProcess; });
  }

  std::vector<ExportSpec> exports;  // in file order
  std::vector<ImportSpec> imports;  // in file order
  DdsSpec dds;                      // defaults when `dds:` is absent

  /// True when the subsystem shares variables with other subsystems (needs the DDS bridge).
  [[nodiscard]] bool has_remote_variables() const { return !exports.empty() || !imports.empty(); }
  [[nodiscard]] const ImportSpec* find_import(std::string_view variable) const {
    for (const auto& i : imports)
      if (i.variable == variable) return &i;
    return nullptr;
  }

  /// The entry that lets task `by` ask for `to` while `from` is on, or nullptr.
  [[nodiscard]] const SwitchRequestSpec* find_request(std::string_view from, std::string_view to,
                                                      std::string_view by) const {
    for (const auto& r : requests)
      if (r.to == to && (r.from.empty() || r.from == from) && (r.by.empty() || r.by == by)) return &r;
    return nullptr;
  }

  [[nodiscard]] const TaskSpec* find_task(std::string_view task_name) const {
    for (const auto& t : tasks)
      if (t.name == task_name) return &t;
    return nullptr;
  }
  [[nodiscard]] const ConfigurationSpec* find_configuration(std::string_view config_name) const {
    for (const auto& c : configurations)
      if (c.name == config_name) return &c;
    return nullptr;
  }
  /// The configurations' names in file order: what a module's switch request names by index.
  [[nodiscard]] std::vector<std::string> configuration_names() const {
    std::vector<std::string> names;
    for (const auto& c : configurations) names.push_back(c.name);
    return names;
  }
};

}  // namespace chimera
