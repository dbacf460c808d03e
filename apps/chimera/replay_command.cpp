// chimera replay DUMP --task NAME: runs one task of a flight-recorder dump on its recorded inputs,
// on the virtual clock, and compares what it writes with what it wrote (docs/flight-recorder.md).
// The dump's subsystem.yaml gives the task; log_player plays variables.csv into its in-vars,
// released twice as often so that each of the task's releases sees that instant's row; its
// in-consts come from the resolved file or the dump's constants.yaml.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include "chimera/config/verify.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "load_file.hpp"

namespace chimera::cli {
namespace {

namespace fs = std::filesystem;

// variables.csv: its columns by name, one value a row.
struct RecordedLog {
  std::vector<std::string> header;
  std::vector<double> times;
  std::vector<std::vector<double>> rows;
};

std::optional<RecordedLog> read_recorded(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) return std::nullopt;
  RecordedLog log;
  std::stringstream header(line);
  for (std::string cell; std::getline(header, cell, ',');) log.header.push_back(cell);
  if (log.header.empty() || log.header[0] != "t") return std::nullopt;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::vector<double> row;
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::strtod(cell.c_str(), nullptr));
    if (row.size() != log.header.size()) return std::nullopt;
    log.times.push_back(row[0]);
    log.rows.push_back(std::move(row));
  }
  if (log.rows.empty()) return std::nullopt;
  return log;
}

bool has_column(const RecordedLog& log, const std::string& variable) {
  return std::find(log.header.begin(), log.header.end(), variable + "[0]") != log.header.end();
}

// The row recorded at `t` (a release of the task), or nullptr.
const std::vector<double>* row_at(const RecordedLog& log, double t) {
  const auto at = std::lower_bound(log.times.begin(), log.times.end(), t - 1e-7);
  return at != log.times.end() && std::abs(*at - t) < 1e-7 ? &log.rows[static_cast<std::size_t>(at - log.times.begin())]
                                                           : nullptr;
}

int fail(const std::string& message) {
  fmt::print(stderr, "replay: {}\n", message);
  return kExitInvalid;
}

// The task's in-vars (played from the log), out-vars the log holds (compared) and in-consts (from
// the file, or the dump's constants.yaml); `problem` says why it cannot be replayed.
struct TaskPorts {
  std::vector<std::string> inputs;
  std::vector<std::string> outputs;
  std::vector<std::pair<std::string, std::vector<double>>> constants;
  std::string problem;
};

TaskPorts ports_of(const ResolvedTask& task, const ResolvedSubsystem& resolved, const RecordedLog& recorded,
                   const std::string& dump) {
  TaskPorts ports;
  const std::string& name = task.spec->name;
  try {
    YAML::Node dumped;
    std::error_code ec;
    if (fs::is_regular_file(dump + "/constants.yaml", ec))
      dumped = YAML::LoadFile(dump + "/constants.yaml")["constants"];
    for (const PortBinding& b : task.bindings) {
      if (b.kind == PortKind::kOutVar && has_column(recorded, b.variable)) ports.outputs.push_back(b.variable);
      if (b.kind == PortKind::kInVar) {
        if (!has_column(recorded, b.variable)) {
          ports.problem =
              fmt::format("'{}' reads {}, which the dump does not hold (no task produced it)", name, b.variable);
          return ports;
        }
        ports.inputs.push_back(b.variable);
      }
      if (b.kind != PortKind::kInConst) continue;
      const auto& known = resolved.constant_values;
      const auto it = std::find_if(known.begin(), known.end(), [&](const auto& c) { return c.first == b.variable; });
      if (it != known.end()) {
        ports.constants.push_back(*it);
      } else if (dumped && dumped[b.variable]) {
        ports.constants.emplace_back(b.variable, dumped[b.variable].as<std::vector<double>>());
      } else {
        ports.problem = fmt::format("'{}' reads the constant {}, whose value the dump does not hold", name, b.variable);
        return ports;
      }
    }
  } catch (const YAML::Exception& e) {
    ports.problem = fmt::format("{}/constants.yaml: {}", dump, e.what());
  }
  return ports;
}

// The file of the replay: the player of the task's inputs (if it reads any), then the task as it ran.
SubsystemSpec replay_spec(const TaskSpec& task, const TaskPorts& ports, const std::string& dump, double from_s) {
  SubsystemSpec spec;
  spec.name = fmt::format("replay_{}", ::getpid());
  spec.file = dump + "/subsystem.yaml";
  spec.constants = ports.constants;
  ConfigurationSpec configuration;
  configuration.name = "replay";
  spec.tasks = {task};
  configuration.tasks = {task.name};
  if (!ports.inputs.empty()) {
    TaskSpec player;
    player.name = task.name == "recorded" ? "recorded_inputs" : "recorded";
    player.module = "log_player";
    player.period_ns = std::max<std::int64_t>(*task.period_ns / 2, 1);  // each release sees its instant's row
    player.criticality = Criticality::kSoft;
    player.params.set("file", fs::absolute(dump + "/variables.csv").string());
    player.params.set("variables", StringList(ports.inputs.begin(), ports.inputs.end()));
    player.params.set("from", from_s);
    spec.tasks.insert(spec.tasks.begin(), player);
    configuration.tasks.insert(configuration.tasks.begin(), player.name);
  }
  spec.configurations = {configuration};
  spec.start = "replay";
  return spec;
}

// What the replayed task did, release by release, against what it was recorded doing.
struct Compared {
  std::uint64_t ran = 0;
  std::uint64_t compared = 0;
  std::map<std::string, double> worst;  // per output: the largest difference from the recorded
  std::map<std::string, double> worst_at;
  std::string fault;
  double fault_at = 0;
};

Compared run_and_compare(Subsystem& subsystem, const RecordedLog& recorded, const std::string& task,
                         const std::vector<std::string>& outputs, std::int64_t period_ns) {
  Compared c;
  const double from_s = recorded.times.front();
  const auto entered_error = [&] {
    for (const auto& snapshot : subsystem.snapshot())
      if (snapshot.name == task && snapshot.state == TaskState::kError) {
        c.fault = snapshot.last_error;
        c.fault_at = from_s + static_cast<double>(snapshot.last_error_ns) * 1e-9;  // on the recorded clock
        return true;
      }
    return false;
  };
  // Release k of the replay is the recorded release from_s + k * period.
  const double window_s = recorded.times.back() - from_s;
  const auto releases = static_cast<std::uint64_t>(std::floor(window_s * 1e9 / static_cast<double>(period_ns))) + 1;
  subsystem.run_for(period_ns / 2);
  for (std::uint64_t k = 0; k < releases && !entered_error(); ++k, subsystem.run_for(period_ns)) {
    const double t = from_s + static_cast<double>(k) * static_cast<double>(period_ns) * 1e-9;
    ++c.ran;
    const std::vector<double>* row = row_at(recorded, t);
    if (row == nullptr) continue;
    ++c.compared;
    for (const auto& out : outputs) {
      const auto value = subsystem.get(out);
      if (!value) continue;
      const auto first = static_cast<std::size_t>(
          std::find(recorded.header.begin(), recorded.header.end(), out + "[0]") - recorded.header.begin());
      for (std::size_t e = 0; e < value->size(); ++e) {
        const double d = std::abs((*value)[e] - (*row)[first + e]);
        if (!(d <= c.worst[out])) {
          c.worst[out] = d;
          c.worst_at[out] = t;
        }
      }
    }
  }
  if (c.fault.empty()) (void)entered_error();  // in the last release
  return c;
}

}  // namespace

int replay_command(const ReplayArgs& args) {
  const std::string dump = fs::path(args.dump).lexically_normal().string();
  const std::string variables_csv = dump + "/variables.csv";
  std::error_code ec;
  if (!fs::is_regular_file(dump + "/subsystem.yaml", ec))
    return fail(
        fmt::format("{}: no subsystem.yaml: not a flight-recorder dump (or one from before it was written)", dump));
  auto original = load_file(dump + "/subsystem.yaml", std::nullopt);
  if (!original) return kExitInvalid;
  const auto recorded = read_recorded(variables_csv);
  if (!recorded) return fail(fmt::format("{}: cannot read it as a dump's variables.csv", variables_csv));

  const Resolution resolution = resolve_subsystem(*original, Registry::global());
  const ResolvedTask* task = resolution.subsystem.find_task(args.task);
  if (task == nullptr) return fail(fmt::format("{}: no task named '{}' in the dump", dump, args.task));
  if (!task->spec->period_ns) return fail(fmt::format("'{}' is aperiodic: replay runs periodic tasks", args.task));
  const TaskPorts ports = ports_of(*task, resolution.subsystem, *recorded, dump);
  if (!ports.problem.empty()) return fail(ports.problem);

  const double from_s = recorded->times.front();
  RunOptions options;
  options.clock = ClockKind::kVirtual;
  auto created = Subsystem::create(replay_spec(*task->spec, ports, dump, from_s), Registry::global(), options);
  if (!created) return fail(created.error().message);
  Subsystem& subsystem = **created;
  if (auto started = subsystem.start(); !started) {
    subsystem.stop();
    return fail(started.error().message);
  }
  const Compared c = run_and_compare(subsystem, *recorded, args.task, ports.outputs, *task->spec->period_ns);
  subsystem.stop();

  fmt::print("replay: task '{}' ({}) of {}, on the virtual clock: {} releases from t = {} s, {}\n", args.task,
             task->spec->module, dump, c.ran, from_s,
             ports.inputs.empty()
                 ? std::string("a task that reads no variable")
                 : fmt::format("its inputs {} played from variables.csv", fmt::join(ports.inputs, ", ")));
  for (const auto& out : ports.outputs) {
    const double worst = c.worst.contains(out) ? c.worst.at(out) : 0.0;
    fmt::print("  {}: at most {:.6g} from the recorded over {} releases{}\n", out, worst, c.compared,
               worst > 0 ? fmt::format(" (the largest at t = {} s)", c.worst_at.at(out)) : "");
  }
  if (!c.fault.empty()) {
    fmt::print("replay: '{}' entered ERROR at the recorded t = {} s: {}\n", args.task, c.fault_at, c.fault);
    return kExitFailed;
  }
  fmt::print("replay: '{}' ran every release without a fault\n", args.task);
  return kExitOk;
}

}  // namespace chimera::cli
