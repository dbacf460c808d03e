#include "detail/task_loader.hpp"

#include <algorithm>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/core/duration_text.hpp"

namespace chimera::config_detail {
namespace {

constexpr int kMaxUserPriority = 1000;
// The shortest period a task may have. The real clock's timer, wake-up and the framework's own
// cycle take microseconds, so a shorter period cannot run there, and on the virtual clock it would
// only make a measuring run (chimera analyze) run billions of cycles.
constexpr std::int64_t kShortestPeriodNs = 10'000;

Result<const ModuleInfo*> read_module(const Source& source, const Field& field, const Registry& registry) {
  auto name = read_text(source, field);
  if (!name) return name.error();
  if (const ModuleInfo* info = registry.find(*name)) return info;
  std::vector<std::string> known;
  for (const ModuleInfo* m : registry.list()) known.push_back(m->name);
  if (known.empty()) return source.fail(field, fmt::format("no module named {} (the module library is empty)", *name));
  return source.fail(field, fmt::format("no module named {} (known: {})", *name, fmt::join(known, ", ")));
}

// period | frequency, deadline, wcet. Zero periods and budgets are refused here because
// parse_duration_ns accepts "0ms" as a duration.
Result<void> read_timing(const Source& source, const MapReader& map, TaskSpec& task) {
  const auto period = map.get("period");
  const auto frequency = map.get("frequency");
  if (period && frequency) return source.fail(*frequency, "give period or frequency, not both");
  if (period || frequency) {
    const Field& f = period ? *period : *frequency;
    auto ns = period ? read_duration(source, f) : read_frequency_period(source, f);
    if (!ns) return ns.error();
    if (*ns <= 0) return source.fail(f, "must be greater than zero");
    if (*ns < kShortestPeriodNs)
      return source.fail(
          f, fmt::format("{}{} is shorter than {}, the shortest period a task can be released at", f.node.Scalar(),
                         period ? "" : fmt::format(" (a period of {})", format_period(*ns)),
                         format_period(kShortestPeriodNs)));
    task.period_ns = *ns;
  }
  task.deadline_ns = task.period_ns.value_or(0);  // an aperiodic task without a deadline has none (0)
  if (const auto f = map.get("deadline")) {
    auto ns = read_duration(source, *f);
    if (!ns) return ns.error();
    if (*ns <= 0) return source.fail(*f, "must be greater than zero");
    task.deadline_ns = *ns;
  }
  if (const auto f = map.get("wcet")) {
    auto ns = read_duration(source, *f);
    if (!ns) return ns.error();
    if (*ns <= 0) return source.fail(*f, "must be greater than zero");
    task.wcet_ns = *ns;
  }
  return {};
}

Result<void> read_criticality(const Source& source, const MapReader& map, TaskSpec& task) {
  const auto f = map.get("criticality");
  if (!f) return {};
  const std::string text = f->node.IsScalar() ? f->node.Scalar() : std::string();
  if (text == "hard") {
    task.criticality = Criticality::kHard;
  } else if (text == "soft") {
    task.criticality = Criticality::kSoft;
  } else {
    return source.fail(*f, fmt::format("{} is not a criticality (use hard or soft)", describe(f->node)));
  }
  return {};
}

// priority, late, virtual_exec and server: how the executive treats the task (docs/scheduling.md).
Result<void> read_priority(const Source& source, const MapReader& map, TaskSpec& task) {
  const auto f = map.get("priority");
  if (!f) return {};
  auto n = read_number(source, *f);
  if (!n) return n.error();
  if (*n != static_cast<double>(static_cast<int>(*n)) || *n < -kMaxUserPriority || *n > kMaxUserPriority)
    return source.fail(*f, fmt::format("{} is not a whole number from -{} to {}", describe(f->node), kMaxUserPriority,
                                       kMaxUserPriority));
  task.priority = static_cast<int>(*n);
  return {};
}

Result<void> read_late(const Source& source, const MapReader& map, TaskSpec& task) {
  task.late = task.criticality == Criticality::kSoft ? LatePolicy::kSkip : LatePolicy::kRun;
  const auto f = map.get("late");
  if (!f) return {};
  const std::string text = f->node.IsScalar() ? f->node.Scalar() : std::string();
  if (text == "run") {
    task.late = LatePolicy::kRun;
  } else if (text == "skip") {
    task.late = LatePolicy::kSkip;
  } else {
    return source.fail(*f, fmt::format("{} is not a late-cycle policy (use run or skip)", describe(f->node)));
  }
  if (!task.period_ns) return source.fail(*f, "only a periodic task has releases to run late or skip");
  return {};
}

Result<void> read_server(const Source& source, const MapReader& map, TaskSpec& task) {
  const auto f = map.get("server");
  if (!f) return {};
  if (task.period_ns)
    return source.fail(*f, "a server is for an aperiodic task (this one has a period; remove one of them)");
  auto server = MapReader::create(source, *f, "a server", {"budget", "period"});
  if (!server) return server.error();
  ServerSpec spec;
  for (auto [key, out] : {std::pair{"budget", &spec.budget_ns}, std::pair{"period", &spec.period_ns}}) {
    auto field = server->require(source, key, "a server has a budget and a period, e.g. { budget: 1ms, period: 10ms }");
    if (!field) return field.error();
    auto ns = read_duration(source, *field);
    if (!ns) return ns.error();
    if (*ns <= 0) return source.fail(*field, "must be greater than zero");
    // A server replenishes its budget every period, as a timer release: the same floor as a task's.
    if (out == &spec.period_ns && *ns < kShortestPeriodNs)
      return source.fail(*field, fmt::format("{} is shorter than {}, the shortest period a server can replenish at",
                                             field->node.Scalar(), format_period(kShortestPeriodNs)));
    *out = *ns;
  }
  if (spec.budget_ns > spec.period_ns)
    return source.fail(*server->get("budget"), "the budget cannot be longer than the server's period");
  task.server = spec;
  if (!map.get("deadline")) task.deadline_ns = spec.period_ns;  // an event is served within a period
  return {};
}

Result<void> read_scheduling(const Source& source, const MapReader& map, TaskSpec& task) {
  if (auto ok = read_priority(source, map, task); !ok) return ok;
  if (auto ok = read_late(source, map, task); !ok) return ok;
  if (const auto f = map.get("virtual_exec")) {
    auto ns = read_duration(source, *f);
    if (!ns) return ns.error();
    task.virtual_exec_ns = *ns;
  }
  return read_server(source, map, task);
}

Result<void> read_cpu(const Source& source, const MapReader& map, const std::vector<int>& cpus, TaskSpec& task) {
  const auto f = map.get("cpu");
  if (!f) return {};
  auto cpu = read_index(source, *f);
  if (!cpu) return cpu.error();
  if (!cpus.empty() && std::find(cpus.begin(), cpus.end(), *cpu) == cpus.end())
    return source.fail(*f, fmt::format("cpu {} is not one of the subsystem's cpus [{}]", *cpu, fmt::join(cpus, ", ")));
  task.cpu = *cpu;
  return {};
}

std::string_view with_article(ParamType t) {
  switch (t) {
    case ParamType::kNumber: return "a number";
    case ParamType::kBool: return "a boolean (true or false)";
    case ParamType::kString: return "a string";
    case ParamType::kVector: return "a list of numbers";
    case ParamType::kMatrix: return "a list of lists of numbers";
    case ParamType::kStringList: return "a list of strings";
  }
  return "?";
}

// An empty list is read as an empty vector, but it is as much an empty matrix or string list.
void fit_empty_list(ParamValue& v, ParamType declared) {
  if (!std::holds_alternative<Vector>(v) || !std::get<Vector>(v).empty()) return;
  if (declared == ParamType::kMatrix) v = Matrix{};
  if (declared == ParamType::kStringList) v = StringList{};
}

// Checks `params:` against the module's declared parameters and fills in the defaults. `lines`
// gets the line of each parameter given, for init's refusals to point at.
Result<Params> read_params(const Source& source, const std::optional<Field>& field, const ModuleInfo& info,
                           std::map<std::string, int>& lines) {
  const Declarations declared = info.declarations(Params{});
  Params params;
  if (field) {
    if (auto ok = check_free_keys(source, *field, "params"); !ok) return ok.error();
    for (const auto& [value, name] : entries(*field)) {
      const std::string& key = name;  // clang-tidy 14 cannot parse a lambda capturing a structured binding
      const auto decl = std::find_if(declared.params().begin(), declared.params().end(),
                                     [&](const ParamDecl& p) { return p.name == key; });
      if (decl == declared.params().end()) {
        std::vector<std::string> known;
        for (const auto& p : declared.params()) known.push_back(p.name);
        std::sort(known.begin(), known.end());
        if (known.empty()) return source.fail(value, fmt::format("unknown parameter ({} takes none)", info.name));
        return source.fail(value,
                           fmt::format("unknown parameter of {} (known: {})", info.name, fmt::join(known, ", ")));
      }
      auto v = read_param_value(source, value);
      if (!v) return v.error();
      fit_empty_list(*v, decl->type);
      if (param_type_of(*v) != decl->type)
        return source.fail(
            value, fmt::format("{} is {}, but {} of {} takes {}", to_string(*v), with_article(param_type_of(*v)), name,
                               info.name, with_article(decl->type)));
      // The declared range or choices: what init would refuse, refused here with the line.
      if (auto why = rule_violation(decl->rule, *v); !why.empty())
        return source.fail(value, fmt::format("{} given: {}", to_string(*v), why));
      params.set(name, *std::move(v));
      lines[name] = value.line;
    }
  }
  for (const auto& p : declared.params())
    if (!params.has(p.name)) params.set(p.name, p.default_value);
  return params;
}

Result<void> read_rename(const Source& source, const Field& field, const ModuleInfo& info, TaskSpec& task) {
  if (auto ok = check_free_keys(source, field, "rename"); !ok) return ok.error();
  const Declarations decls = info.declarations(task.params);
  std::vector<std::string> ports;
  for (const auto& p : decls.ports()) ports.push_back(p.name);
  for (const auto& [value, port] : entries(field)) {
    if (std::find(ports.begin(), ports.end(), port) == ports.end()) {
      if (ports.empty()) return source.fail(value, fmt::format("{} has no ports to rename", info.name));
      return source.fail(value, fmt::format("{} has no port {} (ports: {})", info.name, port, fmt::join(ports, ", ")));
    }
    auto variable = read_variable_name(source, value);
    if (!variable) return variable.error();
    task.rename[port] = *std::move(variable);
  }
  // One variable per port: a task bound twice to one variable would write or read it twice.
  for (const auto& [value, port] : entries(field)) {
    const std::string variable = task.variable_of(port);
    for (const auto& other : ports)
      if (other != port && task.variable_of(other) == variable)
        return source.fail(value, fmt::format("ports {} and {} of {} would both be bound to variable {}", port, other,
                                              task.name, variable));
  }
  return {};
}

// A port not renamed names its variable itself: a module may declare a port name longer than the
// table holds, and the file can still run it by renaming that port.
Result<void> check_port_variable_names(const Source& source, const Field& module_field, const ModuleInfo& info,
                                       const TaskSpec& task) {
  const Declarations decls = info.declarations(task.params);
  for (const auto& p : decls.ports()) {
    const std::string variable = task.variable_of(p.name);
    if (variable.size() > kMaxVariableName)
      return source.fail(module_field, fmt::format("port {} of {} names variable {}, longer than {} characters (the "
                                                   "state variable table's limit): rename it",
                                                   p.name, info.name, variable, kMaxVariableName));
  }
  return {};
}

}  // namespace

Result<TaskSpec> load_task(const Source& source, const Field& task_field, const SubsystemSpec& file,
                           const NameIndex& earlier_tasks, const Registry& registry) {
  auto map = MapReader::create(source, task_field, "a task",
                               {"name", "module", "period", "frequency", "deadline", "criticality", "wcet", "cpu",
                                "priority", "late", "virtual_exec", "server", "params", "rename", "process"});
  if (!map) return map.error();
  TaskSpec task;
  task.loc = SourceLoc{source.file(), task_field.line};

  auto name_field = map->require(source, "name", "every task has a unique name");
  if (!name_field) return name_field.error();
  auto name = read_identifier(source, *name_field, "task name");
  if (!name) return name.error();
  if (const auto first_line = earlier_tasks.find(*name))
    return source.fail(*name_field, fmt::format("task {} is already defined at line {}", *name, *first_line));
  task.name = *std::move(name);

  auto module_field = map->require(source, "module", "the module type this task runs, e.g. pid_joint");
  if (!module_field) return module_field.error();
  auto info = read_module(source, *module_field, registry);
  if (!info) return info.error();
  task.module = (*info)->name;

  if (auto ok = read_timing(source, *map, task); !ok) return ok.error();
  if (auto ok = read_criticality(source, *map, task); !ok) return ok.error();
  if (auto ok = read_scheduling(source, *map, task); !ok) return ok.error();
  if (auto ok = read_cpu(source, *map, file.cpus, task); !ok) return ok.error();
  task.process = file.default_process;
  if (const auto process = map->get("process")) {
    auto process_name = read_process_name(source, *process);
    if (!process_name) return process_name.error();
    task.process = *std::move(process_name);
  }
  auto params = read_params(source, map->get("params"), **info, task.param_lines);
  if (!params) return params.error();
  task.params = *std::move(params);
  if (const auto rename = map->get("rename")) {
    if (auto ok = read_rename(source, *rename, **info, task); !ok) return ok.error();
  }
  if (auto ok = check_port_variable_names(source, *module_field, **info, task); !ok) return ok.error();
  return task;
}

}  // namespace chimera::config_detail
