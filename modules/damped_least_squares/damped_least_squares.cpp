// damped_least_squares: the damped least-squares controller of the paper's Figure 9 (Wampler and
// Leifer): joint velocities that move the tool toward x_d, bounded near a singularity.

#include "module_docs/damped_least_squares.hpp"

#include <cmath>
#include <string>

#include "chimera/module/registry.hpp"
#include "dls_law.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

class DampedLeastSquares final : public Module {
 public:
  static constexpr const char* kName = "damped_least_squares";
  static constexpr const char* kSummary = docs::damped_least_squares::kSummary;
  static constexpr const char* kDoc = docs::damped_least_squares::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    const DlsSettings defaults;
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("x_d", Dim::fixed(6), "desired tool pose [x y z rx ry rz]: m, and a rotation vector in rad");
    d.in_var("x_m", Dim::fixed(6), "measured tool pose, as x_d");
    d.in_var("jacobian", Dim::of("ndof", 6), "geometric Jacobian, 6 x ndof row-major, rows vx vy vz wx wy wz");
    d.out_var("dtheta_d", Dim::of("ndof"), "desired joint velocities, rad/s");
    d.param("gain", defaults.gain, "1/s", "tool twist commanded per unit of pose error").greater_than(0);
    d.param("max_linear_speed", defaults.max_linear_speed, "m/s", "the commanded tool speed is clipped to this")
        .greater_than(0);
    d.param("max_angular_speed", defaults.max_angular_speed, "rad/s", "the commanded tool turn rate is clipped to this")
        .greater_than(0);
    d.param("max_damping", defaults.max_damping, "m", "lambda at a singularity (the damping when w = 0)")
        .greater_than(0);
    d.param("manipulability_threshold", defaults.manipulability_threshold, "",
            "w_0: the damping grows as w falls below it")
        .greater_than(0);
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    const DlsSettings defaults;
    DlsSettings s;
    s.gain = p.number("gain", defaults.gain);
    s.max_linear_speed = p.number("max_linear_speed", defaults.max_linear_speed);
    s.max_angular_speed = p.number("max_angular_speed", defaults.max_angular_speed);
    s.max_damping = p.number("max_damping", defaults.max_damping);
    s.manipulability_threshold = p.number("manipulability_threshold", defaults.manipulability_threshold);
    for (const double v : {s.gain, s.max_linear_speed, s.max_angular_speed, s.max_damping, s.manipulability_threshold})
      if (!(v > 0.0) || !std::isfinite(v))
        return Status::fail(
            "damped_least_squares: gain, speed limits, max_damping and manipulability_threshold must be > 0");
    law_.configure(s);

    x_d_ = ctx.in<double>("x_d");
    x_m_ = ctx.in<double>("x_m");
    jacobian_in_ = ctx.in<double>("jacobian");
    dtheta_d_ = ctx.out<double>("dtheta_d");
    if (ctx.failed()) return Status::ok();  // InitContext names the port that did not bind
    const std::size_t n = dtheta_d_.size();
    if (n > static_cast<std::size_t>(kinematics::kMaxDof))
      return Status::fail(intern("damped_least_squares: ndof is " + std::to_string(n) + ", more than the " +
                                 std::to_string(kinematics::kMaxDof) + " it takes"));
    if (jacobian_in_.size() != 6 * n) return Status::fail("damped_least_squares: jacobian is not 6 x ndof");
    jacobian_ = kinematics::JacobianMatrix::Zero(6, static_cast<Eigen::Index>(n));
    stop();
    return Status::ok();
  }

  Status on() override {
    stop();
    return Status::ok();
  }

  Status cycle() override {
    if (!x_d_.has_data() || !x_m_.has_data() || !jacobian_in_.has_data()) {
      stop();  // no goal or no measurement yet: stand still rather than guess
      return Status::ok();
    }
    const auto n = static_cast<std::size_t>(jacobian_.cols());
    for (std::size_t r = 0; r < 6; ++r)
      for (std::size_t c = 0; c < n; ++c)
        jacobian_(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = jacobian_in_[r * n + c];
    const kinematics::Vector6 v =
        law_.twist(kinematics::pose_from(x_d_.values()), kinematics::pose_from(x_m_.values()));
    law_.update(jacobian_, v, dtheta_d_.values());
    return Status::ok();
  }

  Status off() override {
    stop();
    return Status::ok();
  }

 private:
  void stop() noexcept {
    for (std::size_t i = 0; i < dtheta_d_.size(); ++i) dtheta_d_[i] = 0.0;
  }

  DlsLaw law_;
  kinematics::JacobianMatrix jacobian_;
  In<double> x_d_;
  In<double> x_m_;
  In<double> jacobian_in_;
  Out<double> dtheta_d_;
};

CHIMERA_REGISTER_MODULE(DampedLeastSquares);

}  // namespace
}  // namespace chimera::modules
