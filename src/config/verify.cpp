// Verification of configurations (paper 3.2): rule 1 is eq. (1), no two producers of one
// variable; rule 2 is eq. (2), every input produced; rule 3 is the shape agreement the paper
// leaves implicit. Each configuration is judged on its own.

#include "chimera/config/verify.hpp"

#include <algorithm>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "detail/text.hpp"

namespace chimera {
namespace {

using config_detail::join_names;
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

Ends gather(const ResolvedSubsystem& subsystem, const std::vector<std::string>& task_names) {
  Ends ends;
  for (const auto& [name, value] : subsystem.spec->constants) {
    const VarShape shape{ElemType::kF64, static_cast<std::uint32_t>(value.size())};
    ends.producers[name].push_back(End{nullptr, nullptr, shape});
  }
  for (const auto& i : subsystem.spec->imports)
    ends.producers[i.variable].push_back(End{nullptr, nullptr, VarShape{i.type, i.count}, "imports"});
  for (const auto& t : subsystem.tasks) {
    if (std::find(task_names.begin(), task_names.end(), t.spec->name) == task_names.end()) continue;
    for (const auto& b : t.bindings)
      (is_input(b.kind) ? ends.consumers : ends.producers)[b.variable].push_back(End{&t, &b, b.shape});
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

}  // namespace

std::vector<Violation> verify_tasks(const ResolvedSubsystem& subsystem, const std::vector<std::string>& task_names,
                                    const std::string& configuration_name) {
  Report report(configuration_name);
  for (const auto& name : task_names)
    if (subsystem.find_task(name) == nullptr)
      report.add(0, {}, {name}, fmt::format("no task named {} in the file", name));
  const Ends ends = gather(subsystem, task_names);
  check_rule1(ends, report);
  check_rule2(ends, report);
  check_rule3(ends, report);
  return report.take();
}

std::vector<Violation> verify_subsystem(const Resolution& resolution, const std::optional<std::string>& only) {
  std::vector<Violation> out = resolution.violations;
  const SubsystemSpec& spec = *resolution.subsystem.spec;
  for (const auto& config : spec.configurations) {
    if (only && config.name != *only) continue;
    auto found = verify_tasks(resolution.subsystem, config.tasks, config.name);
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
