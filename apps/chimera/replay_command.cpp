// chimera replay DUMP --task NAME: runs one task of a flight-recorder dump on its recorded inputs,
// on the virtual clock, and compares what it writes with what it wrote (docs/flight-recorder.md).
// The dump's subsystem.yaml gives the task; log_player plays variables.csv into its in-vars,
// released twice as often so that each of the task's releases sees that instant's row, each value
// as the task found it when its cycle started (timing.csv); its in-consts come from the resolved
// file or the dump's constants.yaml.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include "chimera/analysis/release_order.hpp"
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

// timing.csv: per task, per recorded release (ns on the recorded clock), when its cycle started and
// ended, as offsets from the release.
struct CycleTimes {
  std::int64_t start_ns;
  std::int64_t end_ns;
};
using RecordedTiming = std::map<std::string, std::map<std::int64_t, CycleTimes>>;

std::int64_t to_ns(double seconds) { return std::llround(seconds * 1e9); }

RecordedTiming read_timing(const std::string& path) {
  RecordedTiming timing;
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) return timing;  // an older dump without it: played as recorded
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::vector<std::string> cell;
    for (std::string c; std::getline(cells, c, ',');) cell.push_back(c);
    if (cell.size() < 5) continue;
    const std::int64_t latency = std::strtoll(cell[2].c_str(), nullptr, 10);
    const std::int64_t response = std::strtoll(cell[4].c_str(), nullptr, 10);
    timing[cell[0]][to_ns(std::strtod(cell[1].c_str(), nullptr))] = CycleTimes{latency, response};
  }
  return timing;
}

// An input of the replayed task and the task that produced it; `first`: a same-rate predecessor
// (analysis::ReleaseOrder), which at a shared release ran before the task.
struct InputProducer {
  std::string variable;
  std::string producer;
  bool first = false;
};

// The inputs as the task found them: a row holds each variable's value of that instant, but a task
// whose cycle started before its producer's of the same instant had ended (a producer on another
// CPU, or after it in the release order: a loop's back edge) read the value written before. For
// each release of the task and each input, the value played is that of the producer's latest
// release whose cycle had ended when the task's started (timing.csv); where the times cannot tell
// (cycles of no length, on the virtual clock without virtual_exec), the release order does.
// Says how many values were moved back, and the releases whose input the window does not hold (the
// task found a value written before the window began): those are not compared.
struct AsSeen {
  std::size_t moved = 0;
  std::set<std::int64_t> unknown;
};

// Which of the producer's releases wrote the value the task found at `release`, its cycle starting
// at `started`: the latest whose cycle had ended by then. nullopt: one from before the window.
std::optional<std::int64_t> write_seen(const std::map<std::int64_t, CycleTimes>& writes, std::int64_t release,
                                       std::int64_t started, bool producer_first) {
  const auto ended_before = [&](const std::pair<const std::int64_t, CycleTimes>& write) {
    const std::int64_t ended = write.first + write.second.end_ns;
    if (ended != started) return ended < started;
    // A tie: it ran right before if its cycle took time, or if the release order put it first.
    return write.second.start_ns < write.second.end_ns || write.first < release || producer_first;
  };
  auto r = writes.upper_bound(release);
  if (r == writes.begin()) return release;  // no write of it in the window yet: as recorded
  do {
    --r;
  } while (r != writes.begin() && !ended_before(*r));
  if (!ended_before(*r)) return std::nullopt;
  return r->first;
}

AsSeen as_the_task_saw_it(RecordedLog& log, const RecordedTiming& timing, const std::string& task,
                          const std::vector<InputProducer>& input_producers) {
  AsSeen seen_by_task;
  const auto own = timing.find(task);
  if (own == timing.end()) return seen_by_task;
  const RecordedLog original = log;
  for (const InputProducer& input : input_producers) {
    const auto writes = timing.find(input.producer);
    if (writes == timing.end()) continue;
    const auto first = static_cast<std::size_t>(
        std::find(log.header.begin(), log.header.end(), input.variable + "[0]") - log.header.begin());
    std::size_t width = 0;
    while (first + width < log.header.size() && log.header[first + width].rfind(input.variable + "[", 0) == 0) ++width;
    for (const auto& [release, times] : own->second) {
      const std::vector<double>* row = row_at(log, static_cast<double>(release) * 1e-9);
      if (row == nullptr) continue;
      const std::optional<std::int64_t> wrote =
          write_seen(writes->second, release, release + times.start_ns, input.first);
      if (!wrote) {
        seen_by_task.unknown.insert(release);  // it found a value from before the window
        continue;
      }
      if (*wrote == release) continue;  // as recorded
      const std::vector<double>* seen = row_at(original, static_cast<double>(*wrote) * 1e-9);
      if (seen == nullptr) continue;
      auto& target = log.rows[static_cast<std::size_t>(row - log.rows.data())];
      for (std::size_t e = 0; e < width; ++e) target[first + e] = (*seen)[first + e];
      ++seen_by_task.moved;
    }
  }
  return seen_by_task;
}

// A file of the replay's own, removed when it ends (whichever way).
class RemovedAtExit {
 public:
  explicit RemovedAtExit(std::string path) : path_(std::move(path)) {}
  ~RemovedAtExit() {
    std::error_code ignored;
    if (!path_.empty()) fs::remove(path_, ignored);
  }
  RemovedAtExit(const RemovedAtExit&) = delete;
  RemovedAtExit& operator=(const RemovedAtExit&) = delete;
  RemovedAtExit(RemovedAtExit&&) = delete;
  RemovedAtExit& operator=(RemovedAtExit&&) = delete;

 private:
  std::string path_;
};

bool write_log(const RecordedLog& log, const std::string& path) {
  std::ofstream out(path, std::ios::trunc);
  out << fmt::format("{}\n", fmt::join(log.header, ","));
  for (const auto& row : log.rows) out << fmt::format("{}\n", fmt::join(row, ","));
  return static_cast<bool>(out.flush());
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
SubsystemSpec replay_spec(const TaskSpec& task, const TaskPorts& ports, const std::string& dump,
                          const std::string& inputs_csv, double from_s) {
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
    player.params.set("file", fs::absolute(inputs_csv).string());
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
                         const std::vector<std::string>& outputs, std::int64_t period_ns,
                         const std::set<std::int64_t>& not_compared) {
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
    if (row == nullptr || not_compared.contains(to_ns(t))) continue;
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

  // Each input as the task found it at its cycle's start, from timing.csv: a file of its own when
  // that moves any value, removed at the end.
  const analysis::ReleaseOrder order = analysis::compute_release_order(resolution.subsystem);
  const auto index_of = [&](const ResolvedTask* t) { return static_cast<int>(t - resolution.subsystem.tasks.data()); };
  const std::vector<int>& before = order.predecessors[static_cast<std::size_t>(index_of(task))];
  std::vector<InputProducer> producers;
  for (const std::string& input : ports.inputs)
    for (const ResolvedTask& t : resolution.subsystem.tasks)
      for (const PortBinding& b : t.bindings)
        if (b.kind == PortKind::kOutVar && b.variable == input)
          producers.push_back(InputProducer{input, t.spec->name,
                                            std::find(before.begin(), before.end(), index_of(&t)) != before.end()});
  RecordedLog played = *recorded;
  const AsSeen seen = as_the_task_saw_it(played, read_timing(dump + "/timing.csv"), args.task, producers);
  const std::size_t moved = seen.moved;
  std::string inputs_csv = variables_csv;
  if (moved > 0) {
    inputs_csv = (fs::temp_directory_path() / fmt::format("chimera-replay-{}-inputs.csv", ::getpid())).string();
    if (!write_log(played, inputs_csv)) return fail(fmt::format("{}: cannot write the replay's inputs", inputs_csv));
  }
  const RemovedAtExit removed(moved > 0 ? inputs_csv : std::string());

  const double from_s = recorded->times.front();
  RunOptions options;
  options.clock = ClockKind::kVirtual;
  auto created =
      Subsystem::create(replay_spec(*task->spec, ports, dump, inputs_csv, from_s), Registry::global(), options);
  if (!created) return fail(created.error().message);
  Subsystem& subsystem = **created;
  if (auto started = subsystem.start(); !started) {
    subsystem.stop();
    return fail(started.error().message);
  }
  const Compared c =
      run_and_compare(subsystem, *recorded, args.task, ports.outputs, *task->spec->period_ns, seen.unknown);
  subsystem.stop();

  fmt::print("replay: task '{}' ({}) of {}, on the virtual clock: {} releases from t = {} s, {}\n", args.task,
             task->spec->module, dump, c.ran, from_s,
             ports.inputs.empty()
                 ? std::string("a task that reads no variable")
                 : fmt::format("its inputs {} played from variables.csv{}", fmt::join(ports.inputs, ", "),
                               moved == 0 ? std::string()
                                          : fmt::format(", {} value(s) as the task found them: written before "
                                                        "its producer's cycle of the same instant ended (timing.csv)",
                                                        moved)));
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
