// The live assembly of a running subsystem: tasks added and removed, configurations defined and
// verified, the whole saved as a file. Everything is checked before anything changes; an add
// makes the runtime anew (build_runtime), which it may only while no task is created, so that no
// task loses a cycle or its state to it.

#include <algorithm>
#include <mutex>
#include <shared_mutex>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/spec_writer.hpp"
#include "chimera/core/identifier.hpp"
#include "chimera/core/invariant.hpp"
#include "subsystem_impl.hpp"

namespace chimera {

namespace {

std::string live_task_names(const Subsystem::Impl& m) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < m.spec.tasks.size(); ++i)
    if (!m.is_removed(i)) names.push_back(m.spec.tasks[i].name);
  return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

// The first task that is created (OFF, ON or ERROR), or nullptr.
const Task* first_created(const TaskSet& tasks) {
  for (std::size_t i = 0; i < tasks.size(); ++i)
    if (tasks[i].state() != TaskState::kNotCreated) return &tasks[i];
  return nullptr;
}

// "add:7: tasks[2].period: ..." of the loader, for the one entry the operator wrote: "period: ...".
std::string entry_message(std::string_view message) {
  constexpr std::string_view kFile = "add:";
  if (message.starts_with(kFile)) {
    message.remove_prefix(kFile.size());
    if (const auto colon = message.find(": "); colon != std::string_view::npos) message.remove_prefix(colon + 2);
  }
  if (message.starts_with("tasks[")) {
    if (const auto dot = message.find("]."); dot != std::string_view::npos)
      message.remove_prefix(dot + 2);
    else if (const auto colon = message.find("]: "); colon != std::string_view::npos)
      message.remove_prefix(colon + 3);
  }
  return std::string(message);
}

// The subsystem with `entry` appended to its tasks, read as the loader reads a file.
Result<SubsystemSpec> with_task(const SubsystemSpec& current, std::string_view entry, const Registry& registry) {
  std::string text;
  try {
    YAML::Node doc = YAML::Load(write_subsystem_yaml(current));
    const YAML::Node task = YAML::Load(std::string(entry));
    if (!task.IsMap()) return make_error(Errc::kInvalidInput, "add: a task is a mapping, {name: ..., module: ...}");
    doc["tasks"].push_back(task);
    YAML::Emitter out;
    out << doc;
    text = out.c_str();
  } catch (const YAML::Exception& e) {
    return make_error(Errc::kInvalidInput, fmt::format("add: YAML syntax error: {}", e.msg));
  }
  auto loaded = load_subsystem_text(text, "add", registry);
  if (!loaded) return make_error(Errc::kInvalidInput, fmt::format("add: {}", entry_message(loaded.error().message)));
  loaded->file = current.file;
  return loaded;
}

}  // namespace

SubsystemSpec Subsystem::Impl::live_spec() const {
  SubsystemSpec out = spec;
  out.tasks.clear();
  for (std::size_t i = 0; i < spec.tasks.size(); ++i)
    if (!is_removed(i)) out.tasks.push_back(spec.tasks[i]);
  out.start = reconfiguration->configuration();
  return out;
}

Result<void> Subsystem::Impl::rebuild_runtime(SubsystemSpec next, const std::string& configuration,
                                              const SubsystemSpec& current, const std::string& current_configuration) {
  Impl& m = *this;
  std::unique_lock<std::shared_mutex> runtime(m.runtime_mutex);
  // What the runtime that ends leaves for the run to report: its events, faults, a hard failure.
  m.events->collect(*m.tasks);
  const std::vector<Event> drained = m.events->drain();
  {
    std::lock_guard<std::mutex> notes(m.notes_mutex);
    m.earlier_events.insert(m.earlier_events.end(), drained.begin(), drained.end());
  }
  for (auto& line : m.runtime_faults()) m.earlier_faults.push_back(std::move(line));
  m.earlier_hard_failure = m.earlier_hard_failure || m.tasks->hard_task_failed();
  std::vector<SwitchRecord> history = m.reconfiguration->history();
  const std::int64_t now = m.executive->now_ns();
  m.executive->shutdown();
  m.reconfiguration.reset();
  m.executive.reset();
  m.events.reset();
  m.tasks.reset();
  m.requests.reset();  // its slots may be the block's
  m.block.reset();
  m.table.reset();  // the region's name is free again for the new table
  m.spec = std::move(next);
  Result<void> outcome = m.build_runtime(configuration, now);
  if (!outcome) {
    // Only the environment can refuse here (a full /dev/shm, the subsystem's name taken by
    // another process, a worker that cannot start): put back what ran.
    m.spec = current;
    const auto restored = m.build_runtime(current_configuration, now);
    CHIMERA_INVARIANT(restored.ok(), "the subsystem could not be made again as it was");
  }
  // One history of switches for the run, however often its runtime is made: the streams count it.
  m.reconfiguration->carry_history(std::move(history));
  return outcome;
}

Result<std::string> Subsystem::add_task(std::string_view entry) {
  Impl& m = *impl_;
  while (!entry.empty() && entry.front() == ' ') entry.remove_prefix(1);
  while (!entry.empty() && entry.back() == ' ') entry.remove_suffix(1);
  if (entry.find_first_of("\r\n") != std::string_view::npos) return make_error(Errc::kInvalidInput, "add: one line");
  if (!entry.starts_with('{') || !entry.ends_with('}'))
    return make_error(Errc::kInvalidInput,
                      "add: a task as the file writes it, in braces: {name: pid, module: pid_joint, period: 1ms}");

  // Phase 1: check it all while everything runs on.
  SubsystemSpec current;
  {
    std::lock_guard<std::mutex> lock(m.ops_mutex);
    if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
    // A module process reads its tasks from the file: a task the file does not have would shift
    // every index it shares with the main process (docs/processes.md).
    if (m.block)
      return make_error(Errc::kState,
                        "add: not in a subsystem with module processes (process:): their workers "
                        "run the tasks of the file as it was started");
    current = m.live_spec();
  }
  auto next = with_task(current, entry, *m.registry);
  if (!next) return next.error();
  if (auto cpus = check_task_cpus(*next); !cpus) return make_error(Errc::kInvalidInput, "add: " + cpus.error().message);
  {
    // What the new task would break for the whole file (a variable of two shapes); the
    // configurations themselves are verify's, and the new task is in none of them yet.
    const Resolution resolution = resolve_subsystem(*next, *m.registry);
    for (const auto& v : resolution.violations)
      if (v.configuration.empty()) return make_error(Errc::kIllegal, fmt::format("add: {}", v.message));
    // The table has a place of fixed size for every variable: a size no constant fixes yet
    // (ndof before the robot interface that gives it) cannot be laid out.
    for (const auto& v : resolution.subsystem.variables)
      if (v.shape.count == 0)
        return make_error(Errc::kIllegal, fmt::format("add: the size of {} is not known yet: add first the task that "
                                                      "gives the constant sizing it (ndof: the robot interface)",
                                                      v.name));
  }

  // Phase 2: the runtime made anew around the same configuration, its clock going on. The
  // service thread takes ops_mutex to serve a request: it stops before the lock is taken.
  const std::string name = next->tasks.back().name;
  m.executive->stop_serving();
  Result<void> outcome;
  bool serve_again = false;
  {
    std::lock_guard<std::mutex> lock(m.ops_mutex);
    serve_again = m.serving && !m.stopped;
    if (m.stopped) {
      outcome = make_error(Errc::kState, "the subsystem is stopped");
    } else if (const Task* created = first_created(*m.tasks); created != nullptr) {
      outcome = make_error(Errc::kState,
                           fmt::format("add: task {} is {}; a task is added while every task is NOT-CREATED (the "
                                       "executive is made anew for it)",
                                       created->name(), state_name(created->state())));
    } else {
      const std::string configuration = m.reconfiguration->configuration();
      outcome = m.rebuild_runtime(*std::move(next), configuration, current, configuration);
    }
  }
  if (serve_again) serve_requests();
  if (!outcome) return outcome.error();
  return name;
}

Result<void> Subsystem::define_configuration(std::string_view name, const std::vector<std::string>& tasks) {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
  if (!is_identifier(name))
    return make_error(Errc::kInvalidInput,
                      fmt::format("define: '{}' is not a valid configuration name (letters, digits and _, not "
                                  "starting with a digit)",
                                  name));
  if (name == m.reconfiguration->configuration())
    return make_error(Errc::kState,
                      fmt::format("define: configuration '{}' is on; define another and switch to it", name));
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (!m.live_index(tasks[i]))
      return make_error(Errc::kNotFound,
                        fmt::format("define: no task named '{}' (tasks: {})", tasks[i], live_task_names(m)));
    if (std::find(tasks.begin(), tasks.begin() + static_cast<std::ptrdiff_t>(i), tasks[i]) !=
        tasks.begin() + static_cast<std::ptrdiff_t>(i))
      return make_error(Errc::kInvalidInput, fmt::format("define: task {} is listed twice", tasks[i]));
  }
  auto& configurations = m.spec.configurations;
  auto it = std::find_if(configurations.begin(), configurations.end(),
                         [&](const ConfigurationSpec& c) { return c.name == name; });
  if (it != configurations.end()) {
    it->tasks = tasks;
  } else {
    configurations.push_back(ConfigurationSpec{std::string(name), tasks, SourceLoc{m.spec.file, 0}});
  }
  return {};
}

Result<std::vector<Violation>> Subsystem::verify_configuration(std::string_view name) const {
  const Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  const ConfigurationSpec* config = m.spec.find_configuration(name);
  if (config == nullptr) {
    auto known = check_configuration_name(m.spec, name);
    return make_error(Errc::kNotFound, fmt::format("verify: {}", known.error().message));
  }
  return verify_tasks(m.resolution.subsystem, config->tasks, config->name);
}

Result<void> Subsystem::remove_task(std::string_view name) {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
  const auto i = m.live_index(name);
  if (!i) return make_error(Errc::kNotFound, fmt::format("remove: no task named '{}'", name));
  std::vector<std::string> users;
  for (const auto& c : m.spec.configurations)
    if (std::find(c.tasks.begin(), c.tasks.end(), name) != c.tasks.end()) users.push_back(c.name);
  if (!users.empty())
    return make_error(Errc::kState, fmt::format("remove: task {} is in configuration{} {}", name,
                                                users.size() == 1 ? "" : "s", fmt::join(users, ", ")));
  for (const auto& r : m.spec.requests)
    if (r.by == name)
      return make_error(Errc::kState,
                        fmt::format("remove: task {} may ask for a switch to '{}' (the file's requests:)", name, r.to));
  Task& task = (*m.tasks)[*i];
  if (task.state() == TaskState::kOn)
    return make_error(Errc::kState, fmt::format("remove: task {} is ON; turn it off first", name));
  if (task.state() != TaskState::kNotCreated) {
    const Result<void> killed = m.executive->signal(*i, Signal::kKill);
    m.events->collect(*m.tasks);
    m.note_kill(*i, killed);
    if (task.state() != TaskState::kNotCreated)
      return make_error(Errc::kState, fmt::format("remove: task {} could not be killed: {}", name,
                                                  killed ? "it is still created" : killed.error().message));
  }
  std::lock_guard<std::mutex> notes(m.notes_mutex);
  m.removed[*i] = true;
  return {};
}

Result<std::string> Subsystem::save_yaml() const {
  const Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  const SubsystemSpec spec = m.live_spec();
  if (spec.tasks.empty()) return make_error(Errc::kState, "save: the subsystem has no task (a file has at least one)");
  for (const auto& c : spec.configurations) {
    const auto violations = verify_tasks(m.resolution.subsystem, c.tasks, {});
    if (!violations.empty())
      return make_error(Errc::kIllegal, fmt::format("save: configuration '{}' is not legal ({}); define it anew first",
                                                    c.name, violations.front().message));
  }
  std::string text = write_subsystem_yaml(spec);
  // The file must read back as this subsystem; if not, that is the writer's fault, not the user's.
  if (auto back = load_subsystem_text(text, spec.file, *m.registry); !back)
    return make_error(Errc::kInvalidInput,
                      fmt::format("save: internal error, the file does not read back: {}", back.error().message));
  return text;
}

std::vector<std::string> Subsystem::configurations() const {
  std::lock_guard<std::mutex> lock(impl_->ops_mutex);
  std::vector<std::string> names;
  for (const auto& c : impl_->spec.configurations) names.push_back(c.name);
  return names;
}

}  // namespace chimera
