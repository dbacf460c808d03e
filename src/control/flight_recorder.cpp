#include "flight_recorder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/svt/value_codec.hpp"

namespace chimera {

namespace {

// An aperiodic task's records are sized as if it ran at 1 kHz: the memory bound still holds.
constexpr double kAperiodicRateHz = 1000.0;

double rate_hz(const Task& task) {
  return task.periodic() && task.period_ns() > 0 ? 1e9 / static_cast<double>(task.period_ns()) : kAperiodicRateHz;
}

std::uint32_t capacity_for(double seconds, double hz) {
  const double records = std::ceil(seconds * hz) + 1;
  return static_cast<std::uint32_t>(std::clamp(records, 2.0, static_cast<double>(FlightRecorder::kMostRecords)));
}

std::size_t ring_bytes(std::uint32_t capacity, std::uint32_t payload_bytes) {
  return (1 + std::size_t{capacity} * (2 + (payload_bytes + 7) / 8)) * sizeof(std::uint64_t);
}

// A file written whole or an error naming it: a full disk is reported, never a short dump.
class OutFile {
 public:
  explicit OutFile(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "w")) {}
  ~OutFile() {
    if (file_ != nullptr) (void)std::fclose(file_);
  }
  OutFile(const OutFile&) = delete;
  OutFile& operator=(const OutFile&) = delete;
  void put(std::string_view text) {
    if (file_ != nullptr && std::fwrite(text.data(), 1, text.size(), file_) != text.size()) failed_ = errno;
  }
  Result<void> close() {
    if (file_ == nullptr)
      return make_error(Errc::kSystem,
                        fmt::format("dump: cannot write {}: {}", path_, std::generic_category().message(errno)));
    const int closed = std::fclose(file_) == 0 ? 0 : errno;
    file_ = nullptr;
    if (failed_ != 0 || closed != 0)
      return make_error(Errc::kSystem, fmt::format("dump: cannot write {}: {}", path_,
                                                   std::generic_category().message(failed_ != 0 ? failed_ : closed)));
    return {};
  }

 private:
  std::string path_;
  std::FILE* file_;
  int failed_ = 0;
};

// The variables the tasks' out-consts produce, in table order, each once.
std::vector<VarIndex> produced_constants(const ResolvedSubsystem& resolved, const GlobalTable& table) {
  std::vector<VarIndex> out;
  for (const ResolvedTask& t : resolved.tasks)
    for (const PortBinding& b : t.bindings)
      if (b.kind == PortKind::kOutConst)
        if (const auto v = table.find(b.variable)) out.push_back(*v);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

FlightRecorder::FlightRecorder(const ResolvedSubsystem& resolved, const GlobalTable& table, TaskSet& tasks,
                               double seconds)
    : table_(table), tasks_(tasks), seconds_(seconds) {
  // Each variable at its fastest producer's rate; constants and what no task produces are not
  // recorded (they change only by the operator's set, which the operator knows of).
  std::vector<double> var_hz(table.size(), 0.0);
  for (std::size_t i = 0; i < tasks.size(); ++i)
    for (const PortBinding& b : resolved.tasks[i].bindings)
      if (b.kind == PortKind::kOutVar)
        if (const auto v = table.find(b.variable)) var_hz[*v] = std::max(var_hz[*v], rate_hz(tasks[i]));

  constants_ = produced_constants(resolved, table);
  const auto bytes_for = [&](double s) {
    std::size_t total = 0;
    for (std::size_t v = 0; v < var_hz.size(); ++v)
      if (var_hz[v] > 0)
        total += ring_bytes(capacity_for(s, var_hz[v]),
                            static_cast<std::uint32_t>(table.shape(static_cast<VarIndex>(v)).bytes()));
    for (std::size_t i = 0; i < tasks.size(); ++i)
      total += ring_bytes(capacity_for(s, rate_hz(tasks[i])), sizeof(CycleRecord));
    return total;
  };
  if (const std::size_t wanted = bytes_for(seconds_); wanted > kMostBytes) {
    seconds_ *= static_cast<double>(kMostBytes) / static_cast<double>(wanted);
    while (seconds_ > 0 && bytes_for(seconds_) > kMostBytes) seconds_ *= 0.9;
    shortened_ = true;
  }

  ring_of_var_.assign(table.size(), -1);
  for (std::size_t v = 0; v < var_hz.size(); ++v) {
    if (var_hz[v] <= 0) continue;
    const auto var = static_cast<VarIndex>(v);
    const std::size_t ring =
        rings_.add(capacity_for(seconds_, var_hz[v]), static_cast<std::uint32_t>(table.shape(var).bytes()));
    ring_of_var_[v] = static_cast<std::int32_t>(ring);
    variables_.push_back({var, ring});
  }
  for (std::size_t i = 0; i < tasks.size(); ++i)
    timing_ring_.push_back(
        static_cast<std::int32_t>(rings_.add(capacity_for(seconds_, rate_hz(tasks[i])), sizeof(CycleRecord))));
}

void FlightRecorder::bind_tasks() noexcept {
  for (std::size_t i = 0; i < tasks_.size(); ++i) tasks_[i].keep_history(&rings_, timing_ring_[i], ring_of_var_);
}

Result<std::unique_ptr<FlightRecorder>> FlightRecorder::create(const ResolvedSubsystem& resolved,
                                                               const GlobalTable& table, TaskSet& tasks, double seconds,
                                                               Memory memory) {
  std::unique_ptr<FlightRecorder> recorder(new FlightRecorder(resolved, table, tasks, seconds));
  if (memory == Memory::kPrivate) {
    recorder->rings_.allocate();
  } else if (auto made = recorder->rings_.allocate_shared(); !made) {
    return made.error();
  }
  recorder->bind_tasks();
  return recorder;
}

Result<std::unique_ptr<FlightRecorder>> FlightRecorder::attach(const ResolvedSubsystem& resolved,
                                                               const GlobalTable& table, TaskSet& tasks, double seconds,
                                                               int fd) {
  std::unique_ptr<FlightRecorder> recorder(new FlightRecorder(resolved, table, tasks, seconds));
  if (auto mapped = recorder->rings_.attach(fd); !mapped) return mapped.error();
  recorder->bind_tasks();
  return recorder;
}

Result<void> FlightRecorder::write_variables(const std::string& path) const {
  std::vector<HistoryRings::Records> held;
  std::vector<std::int64_t> instants;
  std::string header = "t";
  for (const RecordedVariable& rv : variables_) {
    held.push_back(rings_.read(rv.ring));
    for (const auto& r : held.back()) instants.push_back(r.time_ns);
    const std::size_t count = table_.shape(rv.var).count;
    for (std::size_t e = 0; e < count; ++e) header += fmt::format(",{}[{}]", table_.name(rv.var), e);
  }
  std::sort(instants.begin(), instants.end());
  instants.erase(std::unique(instants.begin(), instants.end()), instants.end());

  OutFile out(path);
  out.put(header + "\n");
  std::vector<std::size_t> next(held.size(), 0);  // per variable: its first record after the row
  std::string row;
  for (const std::int64_t t : instants) {
    row = fmt::format("{}", static_cast<double>(t) / 1e9);
    for (std::size_t k = 0; k < held.size(); ++k) {
      while (next[k] < held[k].size() && held[k][next[k]].time_ns <= t) ++next[k];
      const VarShape shape = table_.shape(variables_[k].var);
      if (next[k] == 0) {
        for (std::size_t e = 0; e < shape.count; ++e) row += ",nan";  // not written yet in the window
        continue;
      }
      // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): the record's words are the value's bytes
      const auto* bytes = reinterpret_cast<const std::byte*>(held[k][next[k] - 1].words.data());
      for (const double value : decode_values(shape, bytes)) row += fmt::format(",{}", value);
    }
    row += '\n';
    out.put(row);
  }
  return out.close();
}

Result<void> FlightRecorder::write_timing(const std::string& path) const {
  OutFile out(path);
  out.put("task,t,latency_ns,exec_ns,response_ns,missed,overrun,failed,skipped\n");
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    for (const auto& r : rings_.read(static_cast<std::size_t>(timing_ring_[i]))) {
      // The record's four words, as Task wrote its CycleRecord.
      const CycleRecord c{static_cast<std::int64_t>(r.words[0]), static_cast<std::int64_t>(r.words[1]),
                          static_cast<std::int64_t>(r.words[2]), r.words[3]};
      const bool skipped = (c.flags & CycleRecord::kSkipped) != 0;
      out.put(fmt::format("{},{},{},{},{},{},{},{},{}\n", tasks_[i].name(), static_cast<double>(r.time_ns) / 1e9,
                          skipped ? 0 : c.latency_ns, c.exec_ns, c.response_ns,
                          (c.flags & CycleRecord::kMissed) != 0 ? 1 : 0, (c.flags & CycleRecord::kOverrun) != 0 ? 1 : 0,
                          (c.flags & CycleRecord::kFailed) != 0 ? 1 : 0, skipped ? c.latency_ns : 0));
    }
  }
  return out.close();
}

Result<void> FlightRecorder::write_constants(const std::string& path) const {
  OutFile out(path);
  out.put(
      "# The constants the tasks produced (out-consts), as they stood at the dump: a `constants:`\n"
      "# map for a file that runs a task of this dump without their producers (log_player, docs/flight-recorder.md).\n"
      "constants:\n");
  for (const VarIndex v : constants_) {
    const VarShape shape = table_.shape(v);
    std::vector<std::byte> bytes(shape.bytes());
    if (table_.read(v, bytes.data(), 0).freshness == Freshness::kNoData) continue;  // its producer never ran init
    out.put(fmt::format("  {}: [{}]\n", table_.name(v), fmt::join(decode_values(shape, bytes.data()), ", ")));
  }
  return out.close();
}

Result<void> FlightRecorder::dump(const std::string& dir, const std::string& why, std::int64_t now_ns,
                                  const std::vector<std::string>& task_lines, const std::string& subsystem_yaml) const {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return make_error(Errc::kSystem, fmt::format("dump: cannot make the directory {}: {}", dir, ec.message()));
  if (auto r = write_variables(dir + "/variables.csv"); !r) return r;
  if (auto r = write_timing(dir + "/timing.csv"); !r) return r;
  OutFile summary(dir + "/summary.txt");
  summary.put(
      fmt::format("chimera flight recorder dump\nwhy: {}\nat: t = {} s\nkept: the last {:.3g} s of every "
                  "produced variable and of every task's cycles\n\n",
                  why, static_cast<double>(now_ns) / 1e9, seconds_));
  for (const auto& line : task_lines) summary.put(line + "\n");
  if (auto r = summary.close(); !r) return r;
  OutFile spec(dir + "/subsystem.yaml");
  spec.put(subsystem_yaml);
  if (auto r = spec.close(); !r) return r;
  return write_constants(dir + "/constants.yaml");
}

}  // namespace chimera
