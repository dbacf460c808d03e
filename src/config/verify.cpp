// Verification of configurations (paper 3.2): rule 1 is eq. (1), no two producers of one
// variable; rule 2 is eq. (2), every input produced; rule 3 is the shape agreement the paper
// leaves implicit. Each configuration is judged on its own.

#include "chimera/config/verify.hpp"

#include <algorithm>
#include <string_view>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "detail/name_index.hpp"
#include "detail/text.hpp"

namespace chimera {
namespace {

using config_detail::join_names;
using config_detail::NameIndex;
using config_detail::shape_text;

// One end of a variable: a task's port, or a source of the file (task == nullptr): `constants:`,
// or `imports:` (the other subsystem that exports the variable produces it).
struct End {
  const ResolvedTask* task = nullptr;
  const PortBinding* port = nullptr;
  VarShape shape;
  const char* source = "constants";

  [[nodiscard]] std::string name() const { return task ? task->spec->name : source; }
  // Renamed ports are named too: the variable alone would not show which output to rename back.
  [[nodiscard]] std::string label() const {
    if (task == nullptr) return source;
    if (port->port == port->variable) return task->spec->name;
    return fmt::format("{} (port {})", task->spec->name, port->port);
  }
};

std::vector<std::string> task_names_of(const std::vector<End>& ends) {
  std::vector<std::string> names;
  for (const auto& e : ends)
    if (e.task) names.push_back(e.task->spec->name);
  return names;
}

std::vector<std::string> labels_of(const std::vector<End>& ends) {
  std::vector<std::string> labels;
  labels.reserve(ends.size());
  for (const auto& e : ends) labels.push_back(e.label());
  return labels;
}

// The producers and consumers of each variable among the tasks of one configuration, sorted by
// variable. Ends are gathered in file order (not list order) so that messages do not depend on
// how a configuration happens to list its tasks.
struct Ends {
  std::map<std::string, std::vector<End>> producers;  // `constants:` and `imports:` first
  std::map<std::string, std::vector<End>> consumers;
};

// Where each task and each constant of the file is (its position), looked up once per name of a
// configuration: the work of judging one is in proportion to its own tasks, not to the file's.
struct FileIndex {
  NameIndex tasks;
  NameIndex constants;
  NameIndex imports;

  explicit FileIndex(const ResolvedSubsystem& subsystem) {
    for (std::size_t i = 0; i < subsystem.tasks.size(); ++i)
      (void)tasks.insert(subsystem.tasks[i].spec->name, static_cast<int>(i));
    for (std::size_t i = 0; i < subsystem.spec->constants.size(); ++i)
      (void)constants.insert(subsystem.spec->constants[i].first, static_cast<int>(i));
    for (std::size_t i = 0; i < subsystem.spec->imports.size(); ++i)
      (void)imports.insert(subsystem.spec->imports[i].variable, static_cast<int>(i));
  }
};

Ends gather(const ResolvedSubsystem& subsystem, const FileIndex& index, const std::vector<std::string>& task_names) {
  // In file order, each task once however often it is listed.
  std::vector<int> positions;
  positions.reserve(task_names.size());
  for (const auto& name : task_names)
    if (const auto at = index.tasks.find(name)) positions.push_back(*at);
  std::sort(positions.begin(), positions.end());
  positions.erase(std::unique(positions.begin(), positions.end()), positions.end());

  Ends ends;
  for (const int at : positions) {
    const ResolvedTask& t = subsystem.tasks[static_cast<std::size_t>(at)];
    for (const auto& b : t.bindings)
      (is_input(b.kind) ? ends.consumers : ends.producers)[b.variable].push_back(End{&t, &b, b.shape});
  }
  // `constants:` and `imports:` only where a task of the configuration uses the variable: alone
  // they can break no rule. They go first among the producers, constants before imports.
  auto add_constant = [&](const std::string& variable) {
    const auto at = index.constants.find(variable);
    if (!at) return;
    const auto& value = subsystem.spec->constants[static_cast<std::size_t>(*at)].second;
    auto& producers = ends.producers[variable];
    if (!producers.empty() && producers.front().task == nullptr) return;  // added already
    const VarShape shape{ElemType::kF64, static_cast<std::uint32_t>(value.size())};
    producers.insert(producers.begin(), End{nullptr, nullptr, shape});
  };
  std::vector<std::string> used;
  for (const auto& [variable, ends_of] : ends.producers) used.push_back(variable);
  for (const auto& [variable, ends_of] : ends.consumers) used.push_back(variable);
  for (const auto& variable : used) add_constant(variable);
  for (const auto& variable : used) {
    const auto at = index.imports.find(variable);
    if (!at) continue;
    const ImportSpec& import = subsystem.spec->imports[static_cast<std::size_t>(*at)];
    auto& producers = ends.producers[variable];
    const auto is_import = [](const End& e) { return e.task == nullptr && std::string_view(e.source) == "imports"; };
    if (std::any_of(producers.begin(), producers.end(), is_import)) continue;  // added already
    const bool after_constant = !producers.empty() && producers.front().task == nullptr;
    producers.insert(producers.begin() + (after_constant ? 1 : 0),
                     End{nullptr, nullptr, VarShape{import.type, import.count}, "imports"});
  }
  return ends;
}

// Collects the violations of one configuration, each message prefixed with its name.
class Report {
 public:
  explicit Report(const std::string& configuration)
      : configuration_(configuration),
        prefix_(configuration.empty() ? "" : fmt::format("configuration '{}': ", configuration)) {}

  void add(int rule, const std::string& variable, std::vector<std::string> tasks, const std::string& text) {
    violations_.push_back({rule, configuration_, variable, std::move(tasks), prefix_ + text});
  }
  std::vector<Violation> take() { return std::move(violations_); }

 private:
  std::string configuration_;
  std::string prefix_;
  std::vector<Violation> violations_;
};

// Eq. (1): the output sets of the configuration's tasks (and `constants:`) do not intersect.
void check_rule1(const Ends& ends, Report& report) {
  for (const auto& [variable, producers] : ends.producers) {
    if (producers.size() < 2) continue;
    // The file's sources come first; they read better last: "by a and by constants".
    const auto first_task = std::find_if(producers.begin(), producers.end(), [](const End& e) { return e.task; });
    const std::vector<End> sources(producers.begin(), first_task);
    const std::vector<End> tasks(first_task, producers.end());
    std::string who = join_names(labels_of(tasks.empty() ? sources : tasks));
    if (!tasks.empty() && !sources.empty()) who = fmt::format("{} and by {}", who, join_names(labels_of(sources)));
    report.add(1, variable, task_names_of(producers), fmt::format("rule 1: {} is produced by {}", variable, who));
  }
}

// Eq. (2): the union of the inputs is a subset of the union of the outputs.
void check_rule2(const Ends& ends, Report& report) {
  for (const auto& [variable, consumers] : ends.consumers) {
    if (ends.producers.contains(variable)) continue;
    report.add(2, variable, task_names_of(consumers),
               fmt::format("rule 2: {} is consumed by {} but produced by no task", variable,
                           join_names(labels_of(consumers))));
  }
}

// Each producer and each of its consumers agree on element type and count.
void check_rule3(const Ends& ends, Report& report) {
  for (const auto& [variable, readers] : ends.consumers) {
    const auto found = ends.producers.find(variable);
    if (found == ends.producers.end()) continue;
    for (const End& writer : found->second) {
      for (const End& reader : readers) {
        // An unsized port (count 0) is already reported as a missing constant (rule 2).
        if (writer.shape.count == 0 || reader.shape.count == 0 || writer.shape == reader.shape) continue;
        std::vector<std::string> tasks;
        if (writer.task != nullptr) tasks.push_back(writer.name());
        tasks.push_back(reader.name());
        report.add(3, variable, std::move(tasks),
                   fmt::format("rule 3: {} is {} from {} but {} reads {}", variable, shape_text(writer.shape),
                               writer.label(), reader.label(), shape_text(reader.shape)));
      }
    }
  }
}

std::vector<Violation> verify_indexed(const ResolvedSubsystem& subsystem, const FileIndex& index,
                                      const std::vector<std::string>& task_names,
                                      const std::string& configuration_name) {
  Report report(configuration_name);
  for (const auto& name : task_names)
    if (!index.tasks.contains(name)) report.add(0, {}, {name}, fmt::format("no task named {} in the file", name));
  const Ends ends = gather(subsystem, index, task_names);
  check_rule1(ends, report);
  check_rule2(ends, report);
  check_rule3(ends, report);
  return report.take();
}

}  // namespace

std::vector<Violation> verify_tasks(const ResolvedSubsystem& subsystem, const std::vector<std::string>& task_names,
                                    const std::string& configuration_name) {
  return verify_indexed(subsystem, FileIndex(subsystem), task_names, configuration_name);
}

std::vector<Violation> verify_subsystem(const Resolution& resolution, const std::optional<std::string>& only) {
  std::vector<Violation> out = resolution.violations;
  const SubsystemSpec& spec = *resolution.subsystem.spec;
  const FileIndex index(resolution.subsystem);  // once for every configuration
  for (const auto& config : spec.configurations) {
    if (only && config.name != *only) continue;
    auto found = verify_indexed(resolution.subsystem, index, config.tasks, config.name);
    out.insert(out.end(), std::make_move_iterator(found.begin()), std::make_move_iterator(found.end()));
  }
  if (only && spec.find_configuration(*only) == nullptr) {
    auto name_ok = check_configuration_name(spec, *only);
    out.push_back({0, *only, {}, {}, name_ok.error().message});
  }
  return out;
}

Result<void> check_configuration_name(const SubsystemSpec& spec, std::string_view name) {
  if (spec.find_configuration(name) != nullptr) return {};
  std::vector<std::string> names;
  for (const auto& c : spec.configurations) names.push_back(c.name);
  return make_error(Errc::kNotFound, fmt::format("{}: no configuration named {} (configurations: {})", spec.file, name,
                                                 fmt::join(names, ", ")));
}

std::string format_violations(const std::vector<Violation>& violations) {
  std::string out;
  for (const auto& v : violations) {
    out += v.message;
    out += '\n';
  }
  return out;
}

}  // namespace chimera
