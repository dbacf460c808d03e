#pragma once
// Resolution (ports bound to variables, sizes fixed) and verification of configurations:
// rule 1 (one producer per variable, the paper's eq. 1), rule 2 (every input produced, eq. 2),
// rule 3 (producer and consumers agree on element type and count).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/config/subsystem.hpp"
#include "chimera/core/result.hpp"
#include "chimera/module/declarations.hpp"
#include "chimera/module/registry.hpp"
#include "chimera/svt/elem_type.hpp"
#include "chimera/svt/port_binding.hpp"

namespace chimera {

/// A task of the file with its ports bound to global variables and their sizes fixed.
struct ResolvedTask {
  const TaskSpec* spec = nullptr;
  const ModuleInfo* module = nullptr;
  Declarations decls;
  std::vector<PortBinding> bindings;  // one per declared port, in declaration order
  bool sized = true;                  // false if some size could not be fixed (see violations)
};

/// The whole file resolved: every task, and the variables of the global table.
struct ResolvedSubsystem {
  const SubsystemSpec* spec = nullptr;
  std::vector<ResolvedTask> tasks;  // same order as spec->tasks
  // Union of every task's variables and `constants`, sorted by name. A variable whose size no
  // port could fix has count 0 (verification reports why, for the configurations that use it).
  std::vector<VarSpec> variables;
  /// Values of every constant known up front: `constants` and declared out-consts.
  std::vector<std::pair<std::string, std::vector<double>>> constant_values;

  [[nodiscard]] const ResolvedTask* find_task(std::string_view name) const {
    for (const auto& t : tasks)
      if (t.spec->name == name) return &t;
    return nullptr;
  }
};

/// One broken rule. `rule` is 1, 2 or 3; `configuration` is empty for file-wide problems
/// (e.g. one variable with two shapes, or a size that cannot be fixed). Rule 0 marks a problem
/// that is none of the paper's rules: a task or configuration name that does not exist, or a
/// module whose declarations size a port by something that is not one of its const ports.
/// `tasks` holds task names only (a `constants:` entry is named in the message).
struct Violation {
  int rule = 0;
  std::string configuration;
  std::string variable;
  std::vector<std::string> tasks;
  std::string message;  // one line, names the rule, the variable and the tasks
};

/// Binds and sizes every task's ports. File-wide problems are returned as violations beside
/// the resolution (a task whose sizes could not be fixed is marked !sized).
struct Resolution {
  ResolvedSubsystem subsystem;
  std::vector<Violation> violations;
};
Resolution resolve_subsystem(const SubsystemSpec& spec, const Registry& registry);

/// Checks rules 1 to 3 for the named tasks (one configuration, or any set of tasks that should
/// be ON together). Messages start with "configuration 'NAME': " unless `configuration_name` is
/// empty; a name that is not a task of the file gives a rule-0 violation. Not real-time safe.
std::vector<Violation> verify_tasks(const ResolvedSubsystem& subsystem, const std::vector<std::string>& task_names,
                                    const std::string& configuration_name);

/// Every configuration of the file (or only `only`), plus the file-wide violations of `resolution`:
/// file-wide ones first, then each configuration's in file order; within one configuration rule 1,
/// then 2, then 3, each by variable name. An `only` that names no configuration adds a rule-0
/// violation; callers that must tell that apart (`chimera verify` exits 2) ask
/// check_configuration_name() first. Not real-time safe.
std::vector<Violation> verify_subsystem(const Resolution& resolution, const std::optional<std::string>& only = {});

/// Succeeds if `name` is a configuration of `spec`; otherwise Errc::kNotFound with a message
/// that lists the configurations. Not real-time safe.
Result<void> check_configuration_name(const SubsystemSpec& spec, std::string_view name);

/// One line per violation (its message), each ending in a newline; "" when there are none.
std::string format_violations(const std::vector<Violation>& violations);

}  // namespace chimera
