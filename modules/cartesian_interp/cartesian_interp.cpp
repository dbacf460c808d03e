// cartesian_interp: Cartesian trajectory interpolation (the paper's Figure 6): the desired tool
// pose x_d moves toward the goal x_goal (from teleop_input, say) on a straight line and the
// shortest rotation, within speed and acceleration limits, for inverse kinematics or resolved
// rate control to follow.

#include "module_docs/cartesian_interp.hpp"

#include <array>
#include <utility>

#include "cartesian_interp/cartesian_motion.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::modules {
namespace {

using cartesian::CartesianMotion;
using cartesian::finite_pose;
using cartesian::Limits;
using kinematics::pose_from;
using kinematics::write_pose;

class CartesianInterp final : public Module {
 public:
  static constexpr const char* kName = "cartesian_interp";
  static constexpr const char* kSummary = docs::cartesian_interp::kSummary;
  static constexpr const char* kDoc = docs::cartesian_interp::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_var("x_goal", Dim::fixed(6), "goal tool pose [x y z rx ry rz], m and rad (NaN: none yet)");
    d.in_var("x_m", Dim::fixed(6), "measured tool pose, m and rad: where the motion starts");
    d.out_var("x_d", Dim::fixed(6), "desired tool pose, m and rad");
    d.out_var("dx_d", Dim::fixed(6), "desired tool velocity [vx vy vz wx wy wz], m/s and rad/s");
    const Limits defaults;
    d.param("speed", defaults.speed, "m/s", "highest speed of the tool point").greater_than(0).less_than(1e6);
    d.param("acceleration", defaults.acceleration, "m/s^2", "highest acceleration of the tool point")
        .greater_than(0)
        .less_than(1e6);
    d.param("angular_speed", defaults.angular_speed, "rad/s", "highest angular speed of the tool")
        .greater_than(0)
        .less_than(1e6);
    d.param("angular_acceleration", defaults.angular_acceleration, "rad/s^2", "highest angular acceleration")
        .greater_than(0)
        .less_than(1e6);
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    limits_.speed = p.number("speed", limits_.speed);
    limits_.acceleration = p.number("acceleration", limits_.acceleration);
    limits_.angular_speed = p.number("angular_speed", limits_.angular_speed);
    limits_.angular_acceleration = p.number("angular_acceleration", limits_.angular_acceleration);
    const std::array<std::pair<const char*, double>, 4> limits = {
        {{"speed", limits_.speed},
         {"acceleration", limits_.acceleration},
         {"angular_speed", limits_.angular_speed},
         {"angular_acceleration", limits_.angular_acceleration}}};
    for (const auto& [name, limit] : limits)
      if (!(limit > 0.0 && limit < 1e6)) return ctx.refuse(name, "cartesian_interp: every limit must be > 0");
    dt_ = ctx.period_s();
    if (dt_ <= 0.0) return Status::fail("cartesian_interp: the task must be periodic (give it a period)");
    x_goal_ = ctx.in<double>("x_goal");
    x_m_ = ctx.in<double>("x_m");
    x_d_ = ctx.out<double>("x_d");
    dx_d_ = ctx.out<double>("dx_d");
    if (ctx.failed()) return Status::ok();  // InitContext names the port that did not bind
    start_from_measurement();
    return Status::ok();
  }

  Status on() override {
    started_ = false;
    start_from_measurement();
    return Status::ok();
  }

  Status cycle() override {
    if (!started_ && !start_from_measurement()) return Status::ok();
    const bool has_goal = x_goal_.has_data() && finite_pose(x_goal_.values());
    motion_.step(has_goal ? pose_from(x_goal_.values()) : motion_.pose(), limits_, dt_);
    publish();
    return Status::ok();
  }

 private:
  // Where the tool is, at rest; false while nothing has measured it.
  bool start_from_measurement() noexcept {
    if (!x_m_.has_data() || !finite_pose(x_m_.values())) return false;
    motion_.reset(pose_from(x_m_.values()));
    publish();
    started_ = true;
    return true;
  }

  void publish() noexcept {
    write_pose(motion_.pose(), x_d_.values());
    for (Eigen::Index i = 0; i < 3; ++i) {
      dx_d_[static_cast<std::size_t>(i)] = motion_.velocity()[i];
      dx_d_[static_cast<std::size_t>(i) + 3] = motion_.angular_velocity()[i];
    }
  }

  Limits limits_;
  double dt_ = 0.0;
  CartesianMotion motion_;
  bool started_ = false;
  In<double> x_goal_;
  In<double> x_m_;
  Out<double> x_d_;
  Out<double> dx_d_;
};

}  // namespace

CHIMERA_REGISTER_MODULE(CartesianInterp);

}  // namespace chimera::modules
