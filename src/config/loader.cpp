// The subsystem file loader (contract section 1). It stops at the first problem and reports it
// as "file:line: key: problem": one clear message is worth more than a cascade of follow-ons.

#include "chimera/config/loader.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "detail/file_text.hpp"
#include "detail/name_index.hpp"
#include "detail/remote_loader.hpp"
#include "detail/request_loader.hpp"
#include "detail/task_loader.hpp"
#include "detail/yaml_reader.hpp"

namespace chimera {
namespace {

using config_detail::element;
using config_detail::entries;
using config_detail::Field;
using config_detail::FileNames;
using config_detail::MapReader;
using config_detail::NameIndex;
using config_detail::Source;

Result<void> read_name(const Source& source, const MapReader& top, SubsystemSpec& spec) {
  auto f = top.require(source, "subsystem", "name the subsystem, e.g. subsystem: arm");
  if (!f) return f.error();
  auto name = config_detail::read_text(source, *f);
  if (!name) return name.error();
  // The name becomes a shared memory object's name: keep it to characters safe there.
  const bool safe = std::all_of(name->begin(), name->end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
  if (!safe)
    return source.fail(*f, fmt::format("\"{}\" is not a valid subsystem name (letters, digits and _ only: it names "
                                       "the subsystem's shared memory)",
                                       *name));
  // Room for what a run adds to it: the region's prefix and, for analyze's measuring runs, a
  // suffix with the pid (the shared memory's limit is 200 characters in all).
  constexpr std::size_t kLongestName = 160;
  if (name->empty() || name->size() > kLongestName)
    return source.fail(*f, fmt::format("a subsystem name has 1 to {} characters, this one {}", kLongestName,
                                       name->size()));
  spec.name = *std::move(name);
  return {};
}

Result<void> read_scheduler(const Source& source, const MapReader& top, SubsystemSpec& spec) {
  const auto f = top.get("scheduler");
  if (!f) return {};
  const std::string text = f->node.IsScalar() ? f->node.Scalar() : std::string();
  for (auto kind : {SchedulerKind::kRm, SchedulerKind::kDm, SchedulerKind::kEdf, SchedulerKind::kMuf}) {
    if (scheduler_name(kind) == text) {
      spec.scheduler = kind;
      return {};
    }
  }
  return source.fail(*f,
                     fmt::format("{} is not a scheduler (use rm, dm, edf or muf)", config_detail::describe(f->node)));
}

Result<void> read_cpus(const Source& source, const MapReader& top, SubsystemSpec& spec) {
  const auto f = top.get("cpus");
  if (!f) return {};
  if (!f->node.IsSequence() || f->node.size() == 0)
    return source.fail(*f, fmt::format("must be a non-empty list of cpu numbers, e.g. [0, 1], not {}",
                                       config_detail::describe(f->node)));
  for (std::size_t i = 0; i < f->node.size(); ++i) {
    const Field e = element(*f, i, f->node[i]);
    auto cpu = config_detail::read_index(source, e);
    if (!cpu) return cpu.error();
    if (std::find(spec.cpus.begin(), spec.cpus.end(), *cpu) != spec.cpus.end())
      return source.fail(e, fmt::format("cpu {} is listed twice", *cpu));
    spec.cpus.push_back(*cpu);
  }
  return {};
}

Result<void> read_plugins(const Source& source, const MapReader& top, std::vector<PluginRef>& plugins) {
  const auto f = top.get("plugins");
  if (!f || f->node.IsNull()) return {};
  if (!f->node.IsSequence())
    return source.fail(*f, fmt::format("must be a list of library names, e.g. [libmy_modules.so], not {}",
                                       config_detail::describe(f->node)));
  for (std::size_t i = 0; i < f->node.size(); ++i) {
    const Field e = element(*f, i, f->node[i]);
    auto name = config_detail::read_text(source, e);
    if (!name) return name.error();
    plugins.push_back(PluginRef{*std::move(name), e.line, e.path});
  }
  return {};
}

Result<void> read_constants(const Source& source, const MapReader& top, SubsystemSpec& spec) {
  const auto f = top.get("constants");
  if (!f) return {};
  if (auto ok = config_detail::check_free_keys(source, *f, "constants"); !ok) return ok.error();
  for (const auto& [value, name] : entries(*f)) {
    if (!is_identifier(name))
      return source.fail(value, "not a valid variable name (letters, digits and _, not starting with a digit)");
    if (auto ok = config_detail::check_variable_name_length(source, value, name); !ok) return ok.error();
    auto numbers = config_detail::read_numbers(source, value);
    if (!numbers) return numbers.error();
    spec.constants.emplace_back(name, *std::move(numbers));
  }
  return {};
}

// The top-level `process:`: the process of tasks that name none (docs/processes.md).
Result<void> read_default_process(const Source& source, const MapReader& top, SubsystemSpec& spec) {
  const auto f = top.get("process");
  if (!f) return {};
  auto name = config_detail::read_process_name(source, *f);
  if (!name) return name.error();
  spec.default_process = *std::move(name);
  return {};
}

Result<void> read_tasks(const Source& source, const MapReader& top, const Registry& registry, SubsystemSpec& spec,
                        NameIndex& task_names) {
  auto f = top.require(source, "tasks", "a subsystem needs at least one task");
  if (!f) return f.error();
  if (!f->node.IsSequence() || f->node.size() == 0)
    return source.fail(
        *f, fmt::format("must be a non-empty list of tasks (- name: ...), not {}", config_detail::describe(f->node)));
  for (std::size_t i = 0; i < f->node.size(); ++i) {
    auto task = config_detail::load_task(source, element(*f, i, f->node[i]), spec, task_names, registry);
    if (!task) return task.error();
    (void)task_names.insert(task->name, task->loc.line);
    spec.tasks.push_back(*std::move(task));
  }
  return {};
}

std::vector<std::string> task_names(const SubsystemSpec& spec) {
  std::vector<std::string> names;
  for (const auto& t : spec.tasks) names.push_back(t.name);
  return names;
}

Result<void> read_configurations(const Source& source, const MapReader& top, SubsystemSpec& spec, FileNames& names) {
  const auto f = top.get("configurations");
  if (!f) {
    // No configurations written: the whole file is the one configuration.
    spec.configurations.push_back(ConfigurationSpec{"default", task_names(spec), SourceLoc{source.file(), 0}});
    (void)names.configurations.insert("default", 0);
    return {};
  }
  if (auto ok = config_detail::check_free_keys(source, *f, "configurations"); !ok) return ok.error();
  if (f->node.IsNull() || f->node.size() == 0)
    return source.fail(*f, "needs at least one configuration (or leave the key out: all tasks form one)");
  for (const auto& [value, name] : entries(*f)) {
    if (!is_identifier(name))
      return source.fail(value, "not a valid configuration name (letters, digits and _, not starting with a digit)");
    if (!value.node.IsSequence())
      return source.fail(value, fmt::format("must be a list of task names, e.g. [traj, pid, robot], not {}",
                                            config_detail::describe(value.node)));
    ConfigurationSpec config{name, {}, SourceLoc{source.file(), value.line}};
    NameIndex listed;
    for (std::size_t i = 0; i < value.node.size(); ++i) {
      const Field e = element(value, i, value.node[i]);
      auto task = config_detail::read_text(source, e);
      if (!task) return task.error();
      if (!names.tasks.contains(*task))
        return source.fail(e, fmt::format("no task named {} (tasks: {})", *task, fmt::join(task_names(spec), ", ")));
      if (listed.insert(*task, e.line)) return source.fail(e, fmt::format("task {} is listed twice", *task));
      config.tasks.push_back(*std::move(task));
    }
    (void)names.configurations.insert(name, value.line);
    spec.configurations.push_back(std::move(config));
  }
  return {};
}

Result<void> read_start(const Source& source, const MapReader& top, SubsystemSpec& spec, const FileNames& names) {
  const auto f = top.get("start");
  if (!f) {
    spec.start = spec.configurations.front().name;
    return {};
  }
  auto name = config_detail::read_text(source, *f);
  if (!name) return name.error();
  if (!names.configurations.contains(*name)) {
    std::vector<std::string> configurations;
    for (const auto& c : spec.configurations) configurations.push_back(c.name);
    return source.fail(
        *f, fmt::format("no configuration named {} (configurations: {})", *name, fmt::join(configurations, ", ")));
  }
  spec.start = *std::move(name);
  return {};
}

// The one document of the file as a checked top-level mapping.
Result<MapReader> read_document(const Source& source, std::string_view text) {
  auto document = config_detail::load_first_document(source, text);
  if (!document) return document.error();
  if (!document->node.IsDefined() || document->node.IsNull())
    return source.fail(1, "", "the file is empty (a subsystem file needs at least subsystem: and tasks:)");
  if (document->second_line)
    return source.fail(*document->second_line, "",
                       "the file holds more than one YAML document (---); write one subsystem per file");
  const Field root{document->node, document->node.Mark().line + 1, ""};
  if (!root.node.IsMap())
    return source.fail(root, fmt::format("the file must be a mapping of keys (subsystem:, tasks:, ...), not {}",
                                         config_detail::describe(root.node)));
  return MapReader::create(
      source, root, "the file",
      {"subsystem", "scheduler", "cpus", "plugins", "constants", "process", "tasks", "configurations", "start",
       "requests", "exports", "imports", "dds"});
}

Result<SubsystemSpec> load(const Source& source, std::string_view text, const Registry& registry) {
  auto top = read_document(source, text);
  if (!top) return top.error();
  SubsystemSpec spec;
  spec.file = source.file();
  // Keys are read in the order a reader meets them in the contract's example; later keys
  // depend on earlier ones (a task's cpu on cpus, configurations on tasks, start on both).
  if (auto ok = read_name(source, *top, spec); !ok) return ok.error();
  if (auto ok = read_scheduler(source, *top, spec); !ok) return ok.error();
  if (auto ok = read_cpus(source, *top, spec); !ok) return ok.error();
  std::vector<PluginRef> plugins;
  if (auto ok = read_plugins(source, *top, plugins); !ok) return ok.error();
  for (auto& p : plugins) spec.plugins.push_back(std::move(p.name));
  if (auto ok = read_constants(source, *top, spec); !ok) return ok.error();
  if (auto ok = read_default_process(source, *top, spec); !ok) return ok.error();
  config_detail::FileNames names;
  if (auto ok = read_tasks(source, *top, registry, spec, names.tasks); !ok) return ok.error();
  if (auto ok = read_configurations(source, *top, spec, names); !ok) return ok.error();
  if (auto ok = read_start(source, *top, spec, names); !ok) return ok.error();
  if (auto ok = config_detail::read_requests(source, top->get("requests"), names, spec); !ok) return ok.error();
  if (auto ok = config_detail::read_exports(source, top->get("exports"), spec); !ok) return ok.error();
  if (auto ok = config_detail::read_imports(source, top->get("imports"), spec); !ok) return ok.error();
  if (auto ok = config_detail::read_dds(source, top->get("dds"), spec); !ok) return ok.error();
  return spec;
}

}  // namespace

Result<SubsystemSpec> load_subsystem_text(std::string_view text, const std::string& file_name,
                                          const Registry& registry) {
  const Source source(file_name);
  if (text.size() > kMaxSubsystemFileBytes)
    return source.fail(1, "",
                       fmt::format("larger than {} bytes, the most a subsystem file may hold", kMaxSubsystemFileBytes));
  // yaml-cpp reports with exceptions and a module's declare() might throw: neither may escape as
  // a crash, since a bad file must end in a message.
  try {
    return load(source, text, registry);
  } catch (const YAML::Exception& e) {
    return source.fail(e.mark.is_null() ? 1 : e.mark.line + 1, "", fmt::format("YAML error: {}", e.msg));
  } catch (const std::exception& e) {
    return make_error(Errc::kInvalidInput, fmt::format("{}: cannot be loaded: {}", file_name, e.what()));
  }
}

Result<SubsystemSpec> load_subsystem_file(const std::string& path, const Registry& registry) {
  auto text = config_detail::read_file_text(path);
  if (!text) return text.error();
  return load_subsystem_text(*text, path, registry);
}

Result<std::vector<PluginRef>> read_plugin_names_text(std::string_view text, const std::string& file_name) {
  const Source source(file_name);
  try {
    auto top = read_document(source, text);
    if (!top) return top.error();
    std::vector<PluginRef> plugins;
    if (auto ok = read_plugins(source, *top, plugins); !ok) return ok.error();
    return plugins;
  } catch (const YAML::Exception& e) {
    return source.fail(e.mark.is_null() ? 1 : e.mark.line + 1, "", fmt::format("YAML error: {}", e.msg));
  }
}

Result<std::vector<PluginRef>> read_plugin_names_file(const std::string& path) {
  auto text = config_detail::read_file_text(path);
  if (!text) return text.error();
  return read_plugin_names_text(*text, path);
}

}  // namespace chimera
