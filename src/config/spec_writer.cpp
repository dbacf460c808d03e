#include "chimera/config/spec_writer.hpp"

#include <variant>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "chimera/core/duration_text.hpp"

namespace chimera {

namespace {

std::string duration(std::int64_t ns) { return exact_duration_text(ns, DurationStyle::kFile); }

// Numbers as the shortest text that reads back exactly (the emitter's own precision may not).
std::string number(double v) { return fmt::format("{}", v); }

void emit_numbers(YAML::Emitter& out, const std::vector<double>& values) {
  out << YAML::Flow << YAML::BeginSeq;
  for (const double v : values) out << number(v);
  out << YAML::EndSeq;
}

void emit_param(YAML::Emitter& out, const ParamValue& value) {
  std::visit(
      [&out](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, double>) {
          out << number(v);
        } else if constexpr (std::is_same_v<T, bool>) {
          out << (v ? "true" : "false");
        } else if constexpr (std::is_same_v<T, std::string>) {
          out << YAML::DoubleQuoted << v;  // "true" or "1" as text stays text
        } else if constexpr (std::is_same_v<T, Vector>) {
          emit_numbers(out, v);
        } else if constexpr (std::is_same_v<T, Matrix>) {
          out << YAML::Flow << YAML::BeginSeq;
          for (const auto& row : v) emit_numbers(out, row);
          out << YAML::EndSeq;
        } else {
          out << YAML::Flow << YAML::BeginSeq;
          for (const auto& s : v) out << YAML::DoubleQuoted << s;
          out << YAML::EndSeq;
        }
      },
      value);
}

// The deadline the loader gives a task that names none: its period, or its server's.
std::int64_t default_deadline(const TaskSpec& t) {
  if (t.period_ns) return *t.period_ns;
  return t.server ? t.server->period_ns : 0;
}

void emit_task(YAML::Emitter& out, const TaskSpec& t) {
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << t.name;
  out << YAML::Key << "module" << YAML::Value << t.module;
  if (t.period_ns) out << YAML::Key << "period" << YAML::Value << duration(*t.period_ns);
  if (t.deadline_ns != default_deadline(t)) out << YAML::Key << "deadline" << YAML::Value << duration(t.deadline_ns);
  out << YAML::Key << "criticality" << YAML::Value << std::string(criticality_name(t.criticality));
  if (t.wcet_ns) out << YAML::Key << "wcet" << YAML::Value << duration(*t.wcet_ns);
  if (t.cpu) out << YAML::Key << "cpu" << YAML::Value << *t.cpu;
  if (t.priority != 0) out << YAML::Key << "priority" << YAML::Value << t.priority;
  if (t.period_ns) out << YAML::Key << "late" << YAML::Value << std::string(late_policy_name(t.late));
  if (t.virtual_exec_ns != 0) out << YAML::Key << "virtual_exec" << YAML::Value << duration(t.virtual_exec_ns);
  if (t.server) {
    out << YAML::Key << "server" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "budget" << YAML::Value << duration(t.server->budget_ns);
    out << YAML::Key << "period" << YAML::Value << duration(t.server->period_ns);
    out << YAML::EndMap;
  }
  if (!t.params.all().empty()) {
    out << YAML::Key << "params" << YAML::Value << YAML::BeginMap;
    for (const auto& [name, value] : t.params.all()) {
      out << YAML::Key << name << YAML::Value;
      emit_param(out, value);
    }
    out << YAML::EndMap;
  }
  if (!t.rename.empty()) {
    out << YAML::Key << "rename" << YAML::Value << YAML::Flow << YAML::BeginMap;
    for (const auto& [port, variable] : t.rename) out << YAML::Key << port << YAML::Value << variable;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
}

// `exports:`, `imports:` and `dds:`, each only when the file had it or it differs from the default.
void emit_remote(YAML::Emitter& out, const SubsystemSpec& spec) {
  if (!spec.exports.empty()) {
    out << YAML::Key << "exports" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const auto& x : spec.exports) out << x.variable;
    out << YAML::EndSeq;
  }
  if (!spec.imports.empty()) {
    out << YAML::Key << "imports" << YAML::Value << YAML::BeginMap;
    for (const auto& i : spec.imports) {
      out << YAML::Key << i.variable << YAML::Value << YAML::Flow << YAML::BeginMap;
      out << YAML::Key << "type" << YAML::Value << std::string(elem_name(i.type));
      out << YAML::Key << "count" << YAML::Value << i.count;
      out << YAML::Key << "max_age" << YAML::Value << duration(i.max_age_ns);
      out << YAML::Key << "reliability" << YAML::Value << std::string(reliability_name(i.reliability));
      out << YAML::Key << "durability" << YAML::Value << std::string(durability_name(i.durability));
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  if (spec.dds.domain != 0 || !spec.dds.partition.empty()) {
    out << YAML::Key << "dds" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "domain" << YAML::Value << spec.dds.domain;
    out << YAML::Key << "partition" << YAML::Value << spec.dds.partition;
    out << YAML::EndMap;
  }
}

}  // namespace

std::string write_subsystem_yaml(const SubsystemSpec& spec) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "subsystem" << YAML::Value << spec.name;
  out << YAML::Key << "scheduler" << YAML::Value << std::string(scheduler_name(spec.scheduler));
  if (!spec.cpus.empty()) out << YAML::Key << "cpus" << YAML::Value << YAML::Flow << spec.cpus;
  if (!spec.plugins.empty()) {
    out << YAML::Key << "plugins" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const auto& p : spec.plugins) out << YAML::DoubleQuoted << p;
    out << YAML::EndSeq;
  }
  if (!spec.constants.empty()) {
    out << YAML::Key << "constants" << YAML::Value << YAML::BeginMap;
    for (const auto& [name, values] : spec.constants) {
      out << YAML::Key << name << YAML::Value;
      if (values.size() == 1)
        out << number(values.front());
      else
        emit_numbers(out, values);
    }
    out << YAML::EndMap;
  }
  out << YAML::Key << "configurations" << YAML::Value << YAML::BeginMap;
  for (const auto& c : spec.configurations) out << YAML::Key << c.name << YAML::Value << YAML::Flow << c.tasks;
  out << YAML::EndMap;
  out << YAML::Key << "start" << YAML::Value << spec.start;
  if (!spec.requests.empty()) {
    out << YAML::Key << "requests" << YAML::Value << YAML::BeginSeq;
    for (const auto& r : spec.requests) {
      out << YAML::Flow << YAML::BeginMap;
      if (!r.from.empty()) out << YAML::Key << "from" << YAML::Value << r.from;
      out << YAML::Key << "to" << YAML::Value << r.to;
      if (!r.by.empty()) out << YAML::Key << "by" << YAML::Value << r.by;
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  out << YAML::Key << "tasks" << YAML::Value << YAML::BeginSeq;
  for (const auto& t : spec.tasks) emit_task(out, t);
  out << YAML::EndSeq;
  emit_remote(out, spec);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace chimera
