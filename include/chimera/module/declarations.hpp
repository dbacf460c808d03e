#pragma once
// What a module declares about itself: its ports (with sizes that may depend on an in-const such
// as ndof) and its parameters. The framework allocates and binds; the module never does.

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "chimera/module/param_rule.hpp"
#include "chimera/module/params.hpp"
#include "chimera/svt/elem_type.hpp"
#include "chimera/svt/port_kind.hpp"

namespace chimera {

/// An element count: `factor` alone, or `factor` times the value of the in-const `symbol`
/// (its first element), e.g. Dim::of("ndof", 6) for a 6 x ndof Jacobian; or, for generic modules
/// such as a join or a logger, whatever size the other ends of the port's variable give it.
struct Dim {
  std::uint32_t factor = 1;
  std::string symbol;    // empty: a fixed count
  bool follows = false;  // true: the size of the variable as another task or `constants:` fixes it

  static Dim fixed(std::uint32_t n) { return Dim{n, {}, false}; }
  static Dim of(std::string symbol, std::uint32_t factor = 1) { return Dim{factor, std::move(symbol), false}; }
  /// The size of the bound variable, fixed by a port of another task (or `constants:`) in the file.
  static Dim follow() { return Dim{1, {}, true}; }
};

/// "6", "ndof", "6*ndof", "any" (a size that follows the variable).
std::string to_string(const Dim& d);

struct PortDecl {
  std::string name;
  PortKind kind;
  ElemType type;
  Dim dim;
  std::vector<double> value;  // out-consts: the value the module will publish, known up front
  std::string doc;
};

struct ParamDecl {
  std::string name;
  ParamType type;
  ParamValue default_value;
  std::string unit;  // "rad", "N*m/rad", "" for none
  std::string doc;
  ParamRule rule{};  // the values it accepts beyond its type (none: any)
};

/// Filled by a module's static declare(Declarations&, const Params&).
class Declarations {
 public:
  template <class T = double>
  void in_const(std::string name, Dim dim, std::string doc) {
    ports_.push_back({std::move(name), PortKind::kInConst, kElemTypeOf<T>, std::move(dim), {}, std::move(doc)});
  }
  template <class T = double>
  void in_var(std::string name, Dim dim, std::string doc) {
    ports_.push_back({std::move(name), PortKind::kInVar, kElemTypeOf<T>, std::move(dim), {}, std::move(doc)});
  }
  template <class T = double>
  void out_var(std::string name, Dim dim, std::string doc) {
    ports_.push_back({std::move(name), PortKind::kOutVar, kElemTypeOf<T>, std::move(dim), {}, std::move(doc)});
  }
  /// Out-consts are f64 and their value is known when the module is declared (from its
  /// parameters), so that verification can size other tasks' ports before anything runs.
  void out_const(std::string name, std::vector<double> value, std::string doc) {
    const auto n = static_cast<std::uint32_t>(value.size());
    ports_.push_back(
        {std::move(name), PortKind::kOutConst, ElemType::kF64, Dim::fixed(n), std::move(value), std::move(doc)});
  }
  /// A parameter with its default; chain a rule on what it returns, in the same statement:
  /// `d.param("cutoff_hz", 10.0, "Hz", "corner frequency").greater_than(0);` (param_rule.hpp).
  ParamRuleBuilder param(std::string name, ParamValue default_value, std::string unit, std::string doc) {
    const ParamType type = param_type_of(default_value);
    params_.push_back({std::move(name), type, std::move(default_value), std::move(unit), std::move(doc), {}});
    return ParamRuleBuilder(params_.back().rule);
  }
  /// The rule of the parameter `name` declared before, or nullptr (the C interface sets rules by
  /// name, after the parameter).
  [[nodiscard]] ParamRule* rule_of(std::string_view name) {
    for (auto& p : params_)
      if (p.name == name) return &p.rule;
    return nullptr;
  }
  /// A mistake in the declarations that no field can hold (a rule for a parameter never
  /// declared): the module is refused at registration with it.
  void refuse(std::string problem) { problems_.push_back(std::move(problem)); }
  [[nodiscard]] const std::vector<std::string>& problems() const { return problems_; }

  /// What the module's resource port talks to (hardware, a simulation, a socket), for docs.
  void resource(std::string what) { resource_ = std::move(what); }
  /// The module is a join connector (the paper's Figure 3): it merges several producers of one
  /// quantity into one output, and Onika draws it as the paper does, not as a module's box.
  void join_connector() { join_connector_ = true; }

  [[nodiscard]] const std::vector<PortDecl>& ports() const { return ports_; }
  [[nodiscard]] const std::vector<ParamDecl>& params() const { return params_; }
  [[nodiscard]] const std::string& resource() const { return resource_; }
  [[nodiscard]] bool is_join_connector() const { return join_connector_; }

 private:
  std::vector<PortDecl> ports_;
  std::vector<ParamDecl> params_;
  std::vector<std::string> problems_;
  std::string resource_;
  bool join_connector_ = false;
};

}  // namespace chimera
