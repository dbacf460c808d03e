#include "detail/declaration_check.hpp"

#include <algorithm>
#include <exception>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "chimera/core/identifier.hpp"

namespace chimera::module_detail {
namespace {

template <class Decl>
bool declared_twice(const std::vector<Decl>& decls, std::size_t i) {
  return std::any_of(decls.begin(), decls.begin() + static_cast<std::ptrdiff_t>(i),
                     [&](const Decl& d) { return d.name == decls[i].name; });
}

std::string check_port(const Declarations& decls, std::size_t i) {
  const auto& ports = decls.ports();
  const PortDecl& p = ports[i];
  if (!is_identifier(p.name))
    return fmt::format("port '{}' is not a valid name (letters, digits and _, not starting with a digit)", p.name);
  if (declared_twice(ports, i)) return fmt::format("port {} is declared twice", p.name);
  if (p.kind == PortKind::kOutConst && p.value.empty())
    return fmt::format("out-const {} has no value (declare it with at least one number)", p.name);
  const Dim& dim = p.dim;
  if (dim.factor == 0) return fmt::format("port {} has size 0", p.name);
  if (dim.follows && !dim.symbol.empty())
    return fmt::format("port {} both follows its variable's size and is sized by {}", p.name, dim.symbol);
  if (dim.symbol.empty()) return {};
  const bool symbol_is_const_port = std::any_of(ports.begin(), ports.end(), [&](const PortDecl& q) {
    return q.name == dim.symbol && is_const(q.kind) && q.type == ElemType::kF64;
  });
  if (!symbol_is_const_port)
    return fmt::format(
        "port {} is sized by {}, which is not one of the module's f64 const ports (declare "
        "in_const(\"{}\", ...) or out_const)",
        p.name, dim.symbol, dim.symbol);
  return {};
}

std::string check_param(const Declarations& decls, std::size_t i) {
  const ParamDecl& p = decls.params()[i];
  if (!is_identifier(p.name))
    return fmt::format("parameter '{}' is not a valid name (letters, digits and _, not starting with a digit)", p.name);
  if (declared_twice(decls.params(), i)) return fmt::format("parameter {} is declared twice", p.name);
  const ParamRule& rule = p.rule;
  const bool numeric = p.type == ParamType::kNumber || p.type == ParamType::kVector || p.type == ParamType::kMatrix;
  const bool textual = p.type == ParamType::kString || p.type == ParamType::kStringList;
  if ((rule.lower || rule.upper || rule.whole) && !numeric)
    return fmt::format("parameter {} is {}, which cannot have a range", p.name, param_type_name(p.type));
  if (!rule.choices.empty() && !textual)
    return fmt::format("parameter {} is {}, which cannot have choices", p.name, param_type_name(p.type));
  if (rule.lower && rule.upper &&
      (*rule.lower > *rule.upper || (*rule.lower == *rule.upper && (rule.lower_exclusive || rule.upper_exclusive))))
    return fmt::format("parameter {}: its range {} holds no value", p.name, describe(rule));
  if (auto why = rule_violation(rule, p.default_value); !why.empty())
    return fmt::format("parameter {}: its default {} breaks its own rule: {}", p.name, to_string(p.default_value), why);
  return {};
}

}  // namespace

Result<void> check_module(const ModuleInfo& info) {
  if (!is_identifier(info.name))
    return make_error(Errc::kInvalidInput,
                      fmt::format("module '{}': not a valid module name (letters, digits and _)", info.name));
  Declarations decls;
  try {
    decls = info.declarations(Params{});
  } catch (const std::exception& e) {
    return make_error(Errc::kInvalidInput, fmt::format("module {}: declare() threw: {}", info.name, e.what()));
  } catch (...) {
    return make_error(Errc::kInvalidInput, fmt::format("module {}: declare() threw", info.name));
  }
  std::string problem = decls.problems().empty() ? std::string() : decls.problems().front();
  for (std::size_t i = 0; i < decls.ports().size() && problem.empty(); ++i) problem = check_port(decls, i);
  for (std::size_t i = 0; i < decls.params().size() && problem.empty(); ++i) problem = check_param(decls, i);
  if (problem.empty()) return {};
  return make_error(Errc::kInvalidInput, fmt::format("module {}: {}", info.name, problem));
}

}  // namespace chimera::module_detail
