// time_integrator: the time integrator of the paper's Figure 9: desired joint positions from
// desired joint velocities, for a position-mode robot driven by a rate controller.

#include "module_docs/time_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "chimera/module/registry.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

constexpr double kDefaultMaxLead = 0.1;  // rad

class TimeIntegrator final : public Module {
 public:
  static constexpr const char* kName = "time_integrator";
  static constexpr const char* kSummary = docs::time_integrator::kSummary;
  static constexpr const char* kDoc = docs::time_integrator::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("dtheta_d", Dim::of("ndof"), "desired joint velocities, rad/s");
    d.in_var("theta_m", Dim::of("ndof"), "measured joint positions, rad (the start, and the bound on the lead)");
    d.out_var("theta_d", Dim::of("ndof"), "desired joint positions, rad");
    d.param("max_lead", kDefaultMaxLead, "rad", "theta_d stays within this of theta_m (0: unbounded)").at_least(0);
    d.param("lower", Vector{}, "rad", "lower bounds on theta_d (one per joint, or one for all); empty: none");
    d.param("upper", Vector{}, "rad", "upper bounds on theta_d; empty: none");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    dt_ = ctx.period_s();
    if (!(dt_ > 0.0)) return Status::fail("time_integrator: the task must be periodic (it integrates over the period)");
    max_lead_ = p.number("max_lead", kDefaultMaxLead);
    if (!(max_lead_ >= 0.0)) return ctx.refuse("max_lead", "time_integrator: max_lead must be >= 0 rad");
    if (max_lead_ == 0.0) max_lead_ = std::numeric_limits<double>::infinity();

    dtheta_d_ = ctx.in<double>("dtheta_d");
    theta_m_ = ctx.in<double>("theta_m");
    theta_d_ = ctx.out<double>("theta_d");
    if (ctx.failed()) return Status::ok();  // InitContext names the port that did not bind
    const std::size_t n = theta_d_.size();
    constexpr double kInf = std::numeric_limits<double>::infinity();
    lower_ = p.vector("lower").empty() ? Vector(n, -kInf) : per_joint(p, "lower", {}, n);
    upper_ = p.vector("upper").empty() ? Vector(n, kInf) : per_joint(p, "upper", {}, n);
    if (lower_.size() != n || upper_.size() != n)
      return ctx.refuse(lower_.size() != n ? "lower" : "upper",
                        "time_integrator: lower and upper need ndof (or 1) finite values");
    for (std::size_t i = 0; i < n; ++i)
      if (!(lower_[i] <= upper_[i]))
        return ctx.refuse("lower", "time_integrator: a lower bound is above its upper one");
    start_from_measurement();
    return Status::ok();
  }

  Status on() override {
    start_from_measurement();
    return Status::ok();
  }

  // theta_d(k+1) = theta_d(k) + dt * dtheta_d: the rectangle rule, one step per period, the
  // rate held over the period as the controller meant it. Bounded so that theta_d never leads the
  // arm by more than max_lead: a robot that cannot follow (a held arm, a joint at its limit) does
  // not make the integral run away.
  Status cycle() override {
    if (!dtheta_d_.has_data()) return Status::ok();
    for (std::size_t i = 0; i < theta_d_.size(); ++i) {
      double next = theta_d_[i] + dt_ * dtheta_d_[i];
      if (theta_m_.has_data()) next = std::clamp(next, theta_m_[i] - max_lead_, theta_m_[i] + max_lead_);
      theta_d_[i] = std::clamp(next, lower_[i], upper_[i]);
    }
    return Status::ok();
  }

 private:
  // The integral starts where the arm is, so that turning the task on moves nothing.
  void start_from_measurement() noexcept {
    if (!theta_m_.has_data()) return;
    for (std::size_t i = 0; i < theta_d_.size(); ++i) theta_d_[i] = std::clamp(theta_m_[i], lower_[i], upper_[i]);
  }

  In<double> dtheta_d_;
  In<double> theta_m_;
  Out<double> theta_d_;
  double dt_ = 0.0;
  double max_lead_ = kDefaultMaxLead;
  Vector lower_;
  Vector upper_;
};

CHIMERA_REGISTER_MODULE(TimeIntegrator);

}  // namespace
}  // namespace chimera::modules
