#pragma once
// Module types for the config tests: the ports of the paper's Figures 3, 4, 8 and 9 (contract
// section 3) without any behaviour, in a registry of their own rather than Registry::global().

#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "chimera/core/identifier.hpp"
#include "chimera/module/module.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::test {

class FakeModule final : public Module {};

inline void add_fake(Registry& registry, std::string name, std::function<void(Declarations&, const Params&)> declare) {
  auto added = registry.add(ModuleInfo{std::move(name), "test module", "", std::move(declare),
                                       []() -> std::unique_ptr<Module> { return std::make_unique<FakeModule>(); }});
  if (!added) std::abort();  // a test fixture bug: two fakes of one name
}

/// The paper's modules (ports as in contract section 3) and a few that exist to break rules.
inline Registry make_test_registry() {
  Registry r;
  const Dim n = Dim::of("ndof");
  add_fake(r, "joint_traj_gen", [n](Declarations& d, const Params&) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.out_var("theta_d", n, "desired joint positions");
    d.out_var("dtheta_d", n, "desired joint velocities");
    d.param("speed", 1.0, "rad/s", "cruise speed");
    d.param("waypoints", Matrix{}, "rad", "joint positions to visit");
  });
  add_fake(r, "pid_joint", [n](Declarations& d, const Params&) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    for (const char* in : {"theta_d", "dtheta_d", "theta_m", "dtheta_m"}) d.in_var(in, n, "joint state");
    d.out_var("tau_r", n, "reference torques");
    d.param("kp", 100.0, "N*m/rad", "proportional gain").at_least(0);
    d.param("ki", 0.0, "N*m/(rad*s)", "integral gain");
    d.param("kd", 10.0, "N*m*s/rad", "derivative gain");
    d.param("enabled", true, "", "output torques at all");
    d.param("label", std::string("pid"), "", "name in logs");
    d.param("limits", Vector{}, "N*m", "torque limits per joint");
    // Declared ranges and choices (module/param_rule.hpp), apart from the free parameters above.
    d.param("form", std::string("pid"), "", "control law").one_of({"pid", "pd"});
    d.param("caps", Vector{}, "N*m", "positive torque caps per joint").greater_than(0);
  });
  // The robot interfaces publish ndof themselves, from a parameter so tests can build a 7-dof arm.
  add_fake(r, "robot_torque", [n](Declarations& d, const Params& p) {
    d.in_var("tau_r", n, "reference torques");
    d.out_var("theta_m", n, "measured joint positions");
    d.out_var("dtheta_m", n, "measured joint velocities");
    d.out_const("ndof", {p.number("dof", 6)}, "degrees of freedom");
    d.param("dof", 6.0, "", "joints of the arm");
  });
  add_fake(r, "robot_position", [n](Declarations& d, const Params& p) {
    d.in_var("theta_d", n, "desired joint positions");
    d.out_var("theta_m", n, "measured joint positions");
    d.out_var("dtheta_m", n, "measured joint velocities");
    d.out_const("ndof", {p.number("dof", 6)}, "degrees of freedom");
    d.param("dof", 6.0, "", "joints of the arm");
  });
  add_fake(r, "fwd_kin_jacobian", [n](Declarations& d, const Params&) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("theta_m", n, "measured joint positions");
    d.out_var("x_m", Dim::fixed(6), "measured end-effector pose");
    d.out_var("jacobian", Dim::of("ndof", 6), "6 x ndof Jacobian");
  });
  add_fake(r, "inv_kin", [n](Declarations& d, const Params&) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("x_d", Dim::fixed(6), "desired pose");
    d.in_var("theta_m", n, "measured joint positions");
    d.out_var("theta_d", n, "desired joint positions");
  });
  add_fake(r, "damped_least_squares", [n](Declarations& d, const Params&) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("x_d", Dim::fixed(6), "desired pose");
    d.in_var("x_m", Dim::fixed(6), "measured pose");
    d.in_var("jacobian", Dim::of("ndof", 6), "6 x ndof Jacobian");
    d.out_var("dtheta_d", n, "desired joint velocities");
    d.param("damping", 0.01, "", "lambda");
  });
  add_fake(r, "time_integrator", [n](Declarations& d, const Params&) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("dtheta_d", n, "desired joint velocities");
    d.in_var("theta_m", n, "measured joint positions");
    d.out_var("theta_d", n, "desired joint positions");
  });
  add_fake(r, "visual_servo", [](Declarations& d, const Params&) {
    d.in_var("x_m", Dim::fixed(6), "measured pose");
    d.out_var("x_d", Dim::fixed(6), "desired pose");
    d.param("gain", 0.5, "", "servo gain");
  });
  // Figure 3's join connector: its number of inputs is a parameter.
  add_fake(r, "join_weighted_average", [n](Declarations& d, const Params& p) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    const int inputs = static_cast<int>(p.number("inputs", 2));
    for (int i = 0; i < inputs; ++i) d.in_var("in_" + std::to_string(i), n, "one input");
    d.out_var("out", n, "weighted average");
    d.param("inputs", 2.0, "", "number of inputs");
  });
  // A generic consumer whose port takes the size its variable has elsewhere in the file.
  add_fake(r, "any_logger", [](Declarations& d, const Params&) {
    d.in_var("theta_m", Dim::follow(), "anything, as sized by its producer");
  });
  add_fake(r, "f32_logger", [](Declarations& d, const Params&) {
    d.in_var<float>("theta_m", Dim::fixed(6), "joint positions, single precision");
  });
  add_fake(r, "bad_sized", [](Declarations& d, const Params&) {
    d.out_var("y", Dim::of("missing_symbol"), "sized by a port that does not exist");
  });
  // A port name one character past what the state variable table holds: runnable only renamed.
  add_fake(r, "long_port", [](Declarations& d, const Params&) {
    d.out_var(std::string(kMaxVariableName + 1, 'p'), Dim::fixed(1), "a port named at length");
  });
  return r;
}

/// One registry of the fakes for a whole test program.
inline const Registry& config_test_registry() {
  static const Registry kRegistry = make_test_registry();
  return kRegistry;
}

}  // namespace chimera::test
