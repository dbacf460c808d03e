// Resolution: every task's ports bound to global variables (after renaming) and sized. Sizes
// that depend on an in-const such as ndof are fixed here, before anything runs, from the values
// the file makes known up front: `constants:` and the declared values of out-consts.

#include <algorithm>
#include <map>
#include <set>

#include <fmt/format.h>

#include "chimera/config/verify.hpp"
#include "detail/text.hpp"

namespace chimera {
namespace {

using config_detail::join_names;
using config_detail::shape_text;
using config_detail::values_text;

constexpr std::uint32_t kMaxSizeValue = 1U << 20;  // far beyond any ndof; keeps counts in range

// One producer of a constant value known before anything runs.
struct KnownValue {
  std::string producer;  // a task name, or "constants"
  std::vector<double> value;
};
using ValueBook = std::map<std::string, std::vector<KnownValue>>;

ValueBook collect_values(const SubsystemSpec& spec, const std::vector<ResolvedTask>& tasks) {
  ValueBook book;
  for (const auto& [name, value] : spec.constants) book[name].push_back({"constants", value});
  for (const auto& t : tasks)
    for (const auto& p : t.decls.ports())
      if (p.kind == PortKind::kOutConst) book[t.spec->variable_of(p.name)].push_back({t.spec->name, p.value});
  return book;
}

bool values_agree(const std::vector<KnownValue>& values) {
  return std::all_of(values.begin(), values.end(),
                     [&](const KnownValue& v) { return v.value == values.front().value; });
}

// The element count of `port` of task `t`, or 0 when it cannot be fixed. Problems other than a
// missing value are file-wide violations; a missing value shows up as rule 2 in every
// configuration that holds the task, which says better what to add.
std::uint32_t count_of(const PortDecl& port, const ResolvedTask& t, const ValueBook& book,
                       std::set<std::string>& size_variables, std::vector<Violation>& violations) {
  const Dim& dim = port.dim;
  if (dim.follows) return 0;  // fixed later from the variable's other ends (fill_followers)
  if (dim.symbol.empty()) return dim.factor;
  const auto& ports = t.decls.ports();
  const auto sym = std::find_if(ports.begin(), ports.end(),
                                [&](const PortDecl& p) { return p.name == dim.symbol && is_const(p.kind); });
  if (sym == ports.end()) {
    violations.push_back({0,
                          {},
                          {},
                          {t.spec->name},
                          fmt::format("task {}: module {} sizes port {} by {}, which is not one of its const ports",
                                      t.spec->name, t.spec->module, port.name, dim.symbol)});
    return 0;
  }
  const std::string variable = t.spec->variable_of(sym->name);
  std::vector<double> value;
  if (sym->kind == PortKind::kOutConst) {
    value = sym->value;  // the task's own constant: no one else's value applies
  } else {
    const auto known = book.find(variable);
    if (known == book.end()) return 0;
    size_variables.insert(variable);
    value = known->second.front().value;
  }
  const double n = value.empty() ? 0.0 : value.front();
  if (!(n >= 1 && n <= kMaxSizeValue && n == static_cast<double>(static_cast<std::uint32_t>(n)))) {
    violations.push_back({3,
                          {},
                          variable,
                          {t.spec->name},
                          fmt::format("rule 3: {} = {} cannot size port {} of task {} (it needs a whole number from 1 "
                                      "to {})",
                                      variable, values_text(value), port.name, t.spec->name, kMaxSizeValue)});
    return 0;
  }
  return dim.factor * static_cast<std::uint32_t>(n);
}

// Ports declared Dim::follow() take the count that the other ends of their variable fix (a sized
// port of any task of the file, or `constants:`). A variable that only followers use has no size
// anywhere: a file-wide violation naming the ports.
void fill_followers(Resolution& out) {
  std::map<std::string, std::uint32_t> counts;
  for (const auto& [name, value] : out.subsystem.spec->constants)
    counts.try_emplace(name, static_cast<std::uint32_t>(value.size()));
  for (const auto& t : out.subsystem.tasks)
    for (std::size_t i = 0; i < t.bindings.size(); ++i)
      if (!t.decls.ports()[i].dim.follows && t.bindings[i].shape.count != 0)
        counts.try_emplace(t.bindings[i].variable, t.bindings[i].shape.count);
  for (auto& t : out.subsystem.tasks) {
    for (std::size_t i = 0; i < t.bindings.size(); ++i) {
      if (!t.decls.ports()[i].dim.follows) continue;
      PortBinding& b = t.bindings[i];
      const auto known = counts.find(b.variable);
      if (known != counts.end()) {
        b.shape.count = known->second;
        continue;
      }
      t.sized = false;
      out.violations.push_back({3,
                                {},
                                b.variable,
                                {t.spec->name},
                                fmt::format("rule 3: port {} of task {} takes its size from variable {}, but no other "
                                            "task or constant of the file gives {} a size",
                                            b.port, t.spec->name, b.variable, b.variable)});
    }
  }
}

// Where a variable's shape was first seen, for the one-shape-per-variable check.
struct ShapeSeen {
  VarShape shape;
  std::string where;  // "task a (port p)" or "constants"
};

void collect_variables(Resolution& out) {
  const SubsystemSpec& spec = *out.subsystem.spec;
  std::map<std::string, ShapeSeen> shapes;
  std::map<std::string, std::string> conflicts;  // variable -> message, one per variable
  auto see = [&](const std::string& variable, const VarShape& shape, const std::string& where) {
    auto [it, inserted] = shapes.try_emplace(variable, ShapeSeen{shape, where});
    if (inserted) return;
    if (it->second.shape.count == 0 && shape.count != 0) {  // an unsized port says nothing yet
      it->second = ShapeSeen{shape, where};
      return;
    }
    if (shape.count == 0 || shape == it->second.shape || conflicts.contains(variable)) return;
    conflicts[variable] =
        fmt::format("rule 3: variable {} is {} in {} and {} in {}; the global table holds one shape per variable",
                    variable, shape_text(it->second.shape), it->second.where, shape_text(shape), where);
  };
  for (const auto& [name, value] : spec.constants)
    see(name, VarShape{ElemType::kF64, static_cast<std::uint32_t>(value.size())}, "constants");
  for (const auto& i : spec.imports) see(i.variable, VarShape{i.type, i.count}, "imports");
  for (const auto& t : out.subsystem.tasks)
    for (const auto& b : t.bindings) see(b.variable, b.shape, fmt::format("task {} (port {})", t.spec->name, b.port));

  for (const auto& [name, seen] : shapes) out.subsystem.variables.push_back(VarSpec{name, seen.shape});
  for (const auto& [variable, message] : conflicts) {
    std::vector<std::string> tasks;
    for (const auto& t : out.subsystem.tasks)
      for (const auto& b : t.bindings)
        if (b.variable == variable) {
          tasks.push_back(t.spec->name);
          break;
        }
    out.violations.push_back({3, {}, variable, std::move(tasks), message});
  }
}

// An export publishes what some task or constant of the file produces: a variable with no producer
// anywhere would publish nothing, ever. Exports travel as Float64MultiArray, so f64 only.
void check_exports(Resolution& out) {
  const SubsystemSpec& spec = *out.subsystem.spec;
  for (const auto& x : spec.exports) {
    std::vector<std::string> producers;
    bool produced = std::any_of(spec.constants.begin(), spec.constants.end(),
                                [&](const auto& c) { return c.first == x.variable; });
    for (const auto& t : out.subsystem.tasks)
      for (const auto& b : t.bindings)
        if (b.variable == x.variable && !is_input(b.kind)) {
          producers.push_back(t.spec->name);
          produced = true;
        }
    if (!produced) {
      out.violations.push_back({2,
                                {},
                                x.variable,
                                {},
                                fmt::format("rule 2: {} is exported (line {}) but no task or constant of the file "
                                            "produces it",
                                            x.variable, x.loc.line)});
      continue;
    }
    const auto var = std::find_if(out.subsystem.variables.begin(), out.subsystem.variables.end(),
                                  [&](const VarSpec& v) { return v.name == x.variable; });
    if (var != out.subsystem.variables.end() && var->shape.type != ElemType::kF64)
      out.violations.push_back({3,
                                {},
                                x.variable,
                                std::move(producers),
                                fmt::format("rule 3: {} is exported (line {}) but is {}; exports travel as f64 "
                                            "(std_msgs/msg/Float64MultiArray)",
                                            x.variable, x.loc.line, shape_text(var->shape))});
  }
}

}  // namespace

Resolution resolve_subsystem(const SubsystemSpec& spec, const Registry& registry) {
  Resolution out;
  out.subsystem.spec = &spec;
  for (const auto& task : spec.tasks) {
    ResolvedTask t;
    t.spec = &task;
    t.module = registry.find(task.module);
    if (t.module == nullptr) {
      // The loader refuses unknown modules; a spec built by hand may still hold one.
      t.sized = false;
      out.violations.push_back(
          {0, {}, {}, {task.name}, fmt::format("task {}: no module named {} in the library", task.name, task.module)});
    } else {
      t.decls = t.module->declarations(task.params);
    }
    out.subsystem.tasks.push_back(std::move(t));
  }

  const ValueBook book = collect_values(spec, out.subsystem.tasks);
  // One value per variable, the first in the file; disagreements matter only where they fix a
  // size (below) or where two producers are ON together (rule 1).
  for (const auto& [variable, values] : book)
    out.subsystem.constant_values.emplace_back(variable, values.front().value);

  std::set<std::string> size_variables;  // constants that fix some port's size
  for (auto& t : out.subsystem.tasks) {
    for (const auto& port : t.decls.ports()) {
      const std::uint32_t count = count_of(port, t, book, size_variables, out.violations);
      if (count == 0 && !port.dim.symbol.empty()) t.sized = false;
      t.bindings.push_back(
          PortBinding{port.name, t.spec->variable_of(port.name), port.kind, VarShape{port.type, count}});
    }
  }

  // Sizes fixed from a constant with two different values would differ between configurations,
  // but the global table holds one shape per variable.
  for (const auto& variable : size_variables) {
    const auto& values = book.at(variable);
    if (values_agree(values)) continue;
    std::vector<std::string> producers;
    std::vector<std::string> parts;
    for (const auto& v : values) {
      if (v.producer != "constants") producers.push_back(v.producer);
      parts.push_back(fmt::format("{} from {}", values_text(v.value), v.producer));
    }
    out.violations.push_back(
        {3,
         {},
         variable,
         std::move(producers),
         fmt::format("rule 3: {} sizes ports but has different values in the file: {}", variable, join_names(parts))});
  }

  fill_followers(out);
  collect_variables(out);
  check_exports(out);
  return out;
}

}  // namespace chimera
