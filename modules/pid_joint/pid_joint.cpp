// pid_joint: the PID joint position controller of the paper's Figure 4.

#include "module_docs/pid_joint.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string_view>

#include "chimera/module/fault_tolerance.hpp"
#include "chimera/module/registry.hpp"
#include "pid_law.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

// Tuned for the shipped arm (sim/models/arm6.xml) at 1 kHz: about 0.01 rad worst tracking error
// on joint_traj_gen's default motion, and stable with three times the proportional gain.
Vector default_kp() { return {2500, 4000, 2500, 400, 400, 300}; }
Vector default_ki() { return {2500, 5000, 2500, 300, 300, 200}; }
Vector default_kd() { return {150, 200, 100, 20, 20, 15}; }
Vector default_tau_max() { return {150, 150, 80, 20, 20, 20}; }
Vector default_i_max() { return {0.05, 0.05, 0.05, 0.05, 0.05, 0.05}; }

constexpr double kDefaultLateLimit = 100;

class PidJoint final : public Module {
 public:
  static constexpr const char* kName = "pid_joint";
  static constexpr const char* kSummary = docs::pid_joint::kSummary;
  static constexpr const char* kDoc = docs::pid_joint::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("theta_d", Dim::of("ndof"), "desired joint positions, rad");
    d.in_var("dtheta_d", Dim::of("ndof"), "desired joint velocities, rad/s");
    d.in_var("theta_m", Dim::of("ndof"), "measured joint positions, rad");
    d.in_var("dtheta_m", Dim::of("ndof"), "measured joint velocities, rad/s");
    d.out_var("tau_r", Dim::of("ndof"), "reference joint torques, N*m");
    d.param("kp", default_kp(), "N*m/rad", "proportional gains (one per joint, or one for all)").at_least(0);
    d.param("ki", default_ki(), "N*m/(rad*s)", "integral gains").at_least(0);
    d.param("kd", default_kd(), "N*m*s/rad", "derivative gains, on the velocity error").at_least(0);
    d.param("tau_max", default_tau_max(), "N*m", "output saturation per joint").at_least(0);
    d.param("i_max", default_i_max(), "rad*s", "bound on the integral of the position error").at_least(0);
    d.param("late_limit", kDefaultLateLimit, "cycles",
            "timing faults (late cycles, budget overruns) in a row that error() recovers from before ERROR")
        .whole()
        .at_least(1);
  }

 protected:
  Status init(InitContext& ctx) override {
    ndof_ = ctx.in<double>("ndof");
    theta_d_ = ctx.in<double>("theta_d");
    dtheta_d_ = ctx.in<double>("dtheta_d");
    theta_m_ = ctx.in<double>("theta_m");
    dtheta_m_ = ctx.in<double>("dtheta_m");
    tau_r_ = ctx.out<double>("tau_r");
    // An unbound view already fails init with a message naming the port (InitContext's rule).
    if (ctx.failed()) return Status::ok();
    if (!ndof_matches()) return Status::fail("pid_joint: in-const ndof differs from the size of its ports");
    const std::size_t n = tau_r_.size();
    const double dt = ctx.period_s();
    if (!(dt > 0.0)) return Status::fail("pid_joint: the task must be periodic (the integral uses the period)");

    const Params& p = ctx.params();
    PidGains g;
    g.kp = per_joint(p, "kp", default_kp(), n);
    g.ki = per_joint(p, "ki", default_ki(), n);
    g.kd = per_joint(p, "kd", default_kd(), n);
    g.tau_max = per_joint(p, "tau_max", default_tau_max(), n);
    g.i_max = per_joint(p, "i_max", default_i_max(), n);
    const bool valid = !g.kp.empty() && !g.ki.empty() && !g.kd.empty() && !g.tau_max.empty() && !g.i_max.empty() &&
                       all_non_negative(g.kp) && all_non_negative(g.ki) && all_non_negative(g.kd) &&
                       all_non_negative(g.tau_max) && all_non_negative(g.i_max);
    if (!valid) return Status::fail("pid_joint: kp, ki, kd, tau_max and i_max need ndof (or 1) values, none negative");
    law_.configure(std::move(g), dt);
    timing_ = &ctx.timing();
    tolerance_ =
        TimingFaultTolerance(static_cast<std::uint64_t>(std::max(1.0, p.number("late_limit", kDefaultLateLimit))));
    return Status::ok();
  }

  // A late torque update is only late: recover, unless the lateness goes on (see late_limit).
  Status error() override { return tolerance_.judge(*timing_); }

  // A new producer of ndof took over: fine as long as the arm has as many joints as before.
  Status reinit() override {
    return ndof_matches() ? Status::ok() : Status::fail("pid_joint: in-const ndof changed; respawn the task");
  }

  Status on() override {
    law_.reset();
    zero_output();
    return Status::ok();
  }

  Status cycle() override {
    if (!theta_d_.has_data() || !dtheta_d_.has_data() || !theta_m_.has_data() || !dtheta_m_.has_data()) {
      zero_output();  // no target or no measurement yet: let the arm be rather than guess
      return Status::ok();
    }
    law_.update(theta_d_.values(), dtheta_d_.values(), theta_m_.values(), dtheta_m_.values(), tau_r_.values());
    return Status::ok();
  }

  Status off() override {
    zero_output();
    return Status::ok();
  }

 private:
  // The resolver sized the ports from ndof before anything ran, so the sizes are the truth; the
  // value itself may not be in the table yet when tasks are spawned before its producer.
  [[nodiscard]] bool ndof_matches() const noexcept {
    if (!ndof_.has_data() || ndof_[0] == 0.0) return true;
    return ndof_[0] == static_cast<double>(tau_r_.size());
  }

  void zero_output() noexcept {
    for (std::size_t i = 0; i < tau_r_.size(); ++i) tau_r_[i] = 0.0;
  }

  In<double> ndof_;
  In<double> theta_d_;
  In<double> dtheta_d_;
  In<double> theta_m_;
  In<double> dtheta_m_;
  Out<double> tau_r_;
  PidLaw law_;
  const CycleTiming* timing_ = nullptr;
  TimingFaultTolerance tolerance_{static_cast<std::uint64_t>(kDefaultLateLimit)};
};

CHIMERA_REGISTER_MODULE(PidJoint);

}  // namespace
}  // namespace chimera::modules
