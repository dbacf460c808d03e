#include "api_documents.hpp"

#include <string>
#include <variant>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/control/control.hpp"
#include "chimera/module/declarations.hpp"
#include "chimera/module/param_rule.hpp"
#include "chimera/svt/elem_type.hpp"
#include "chimera/svt/port_kind.hpp"
#include "example_files.hpp"

namespace chimera::net {

namespace {

using nlohmann::json;

json module_json(const Registry& registry, const ModuleInfo& m) {
  // Ports may depend on parameters; the defaults show the usual shape, as `chimera modules M`.
  const Declarations decls = m.declarations(Params{});
  json ports = json::array();
  for (const auto& p : decls.ports()) {
    json port{{"name", p.name},
              {"kind", port_kind_name(p.kind)},
              {"type", elem_name(p.type)},
              {"size", to_string(p.dim)},
              {"doc", p.doc}};
    if (!p.value.empty()) port["value"] = p.value;
    ports.push_back(std::move(port));
  }
  json params = json::array();
  for (const auto& p : decls.params()) {
    const std::string accepts = describe(p.rule);
    params.push_back(json{{"name", p.name},
                          {"type", param_type_name(p.type)},
                          {"default", to_string(p.default_value)},
                          {"accepts", accepts.empty() ? "any" : accepts},
                          {"unit", p.unit},
                          {"doc", p.doc}});
  }
  return json{{"name", m.name},
              {"summary", m.summary},
              {"doc", m.doc},
              {"library", registry.origin(m.name)},
              {"resource", decls.resource()},
              {"connector", decls.is_join_connector() ? "join" : ""},
              {"ports", std::move(ports)},
              {"params", std::move(params)}};
}

json task_model_json(const ResolvedTask& t) {
  const TaskSpec& spec = *t.spec;
  // The parameters as JSON values, so that the page can write the task's entry back (JSON is a
  // YAML flow mapping) when it adds the task anew with another rename.
  json params = json::object();
  for (const auto& [name, value] : spec.params.all())
    std::visit([&, &key = name](const auto& v) { params[key] = v; }, value);
  json ports = json::array();
  for (const auto& b : t.bindings)
    ports.push_back(json{{"port", b.port},
                         {"variable", b.variable},
                         {"kind", port_kind_name(b.kind)},
                         {"shape", to_string(b.shape)},
                         {"renamed", b.port != b.variable}});
  json task{{"name", spec.name},       {"module", spec.module},    {"criticality", criticality_name(spec.criticality)},
            {"process", spec.process}, {"sized", t.sized},         {"params", std::move(params)},
            {"rename", spec.rename},   {"ports", std::move(ports)},
            {"connector", t.decls.is_join_connector() ? "join" : ""}};
  task["period_ns"] = spec.period_ns ? json(*spec.period_ns) : json(nullptr);
  task["cpu"] = spec.cpu ? json(*spec.cpu) : json(nullptr);
  return task;
}

}  // namespace

json violations_json(const std::vector<Violation>& violations) {
  json out = json::array();
  for (const auto& v : violations)
    out.push_back(json{{"rule", v.rule},
                       {"variable", v.variable},
                       {"tasks", v.tasks},
                       {"reason", violation_reason(v)},
                       {"message", v.message}});
  return out;
}

json module_library_json(const Registry& registry) {
  json modules = json::array();
  for (const ModuleInfo* m : registry.list()) modules.push_back(module_json(registry, *m));
  return modules;
}

json subsystem_model_json(const Subsystem& subsystem) {
  json tasks = json::array();
  const auto& resolved = subsystem.resolved().tasks;
  for (std::size_t i = 0; i < resolved.size(); ++i)
    if (!subsystem.removed(i)) tasks.push_back(task_model_json(resolved[i]));  // a removed task is gone
  json configurations = json::array();
  for (const auto& c : subsystem.spec().configurations) {
    json configuration{{"name", c.name}, {"tasks", c.tasks}};
    if (auto violations = subsystem.verify_configuration(c.name)) {
      configuration["legal"] = violations->empty();
      configuration["violations"] = violations_json(*violations);
    }
    configurations.push_back(std::move(configuration));
  }
  return json{{"subsystem", subsystem.spec().name},
              {"configuration", subsystem.configuration()},
              {"illegal_configuration", subsystem.illegal_configuration()},
              {"tasks", std::move(tasks)},
              {"configurations", std::move(configurations)}};
}

json examples_json() {
  json list = json::array();
  for (const auto& e : example_files()) list.push_back(json{{"name", e.name}, {"title", e.title}, {"text", e.text}});
  return list;
}

}  // namespace chimera::net
