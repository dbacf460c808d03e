// cartesian_interp: Cartesian trajectory interpolation (the paper's Figure 6): the desired tool
// pose x_d moves toward the goal x_goal (from teleop_input, say) on a straight line and the
// shortest rotation, within speed and acceleration limits, for inverse kinematics or resolved
// rate control to follow.

#include "cartesian_interp/cartesian_motion.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::modules {
namespace {

using cartesian::CartesianMotion;
using cartesian::finite_pose;
using cartesian::Limits;
using cartesian::pose_of;
using cartesian::write_pose;

class CartesianInterp final : public Module {
 public:
  static constexpr const char* kName = "cartesian_interp";
  static constexpr const char* kSummary = "Cartesian trajectory interpolation: x_d toward x_goal within speed limits";
  static constexpr const char* kDoc =
      "The *Cartesian trajectory interpolator* of the paper's Figure 6 (Cartesian teleoperation): it\n"
      "turns a goal pose that jumps (each command of an operator, from\n"
      "[teleop_input](teleop_input.md)) into a desired tool pose `x_d` that moves smoothly toward it,\n"
      "for inverse kinematics (`inv_kin`) or resolved-rate control (`damped_least_squares` and\n"
      "`time_integrator`) to follow."
      "\n\n"
      "Poses are [x y z rx ry rz]: m, and "
      "a rotation vector in rad, in the arm's base frame. Turned on, x_d starts at the measured pose "
      "x_m, at rest. Each cycle of dt it moves toward the goal x_goal: the position along the straight "
      "line to the goal's, the orientation about the fixed axis of the shortest rotation to the "
      "goal's, each with a speed that never exceeds speed (m/s) or angular_speed (rad/s), changes by "
      "at most acceleration dt (m/s^2) or angular_acceleration dt (rad/s^2) per cycle, and is at most "
      "the speed from which it can still stop exactly on the goal: at a distance d, with x = d / (a "
      "dt^2), a dt (x / (N + 1) + N / 2) for the whole N with N (N + 1) / 2 < x <= (N + 1) (N + 2) / 2 "
      "(a trapezoidal profile in discrete time, landing on the goal without overshoot). A goal that moves "
      "is followed the same way, the velocity turning within the acceleration limits. dx_d is the "
      "velocity [v; w]. While x_goal has no data or is not finite (NaN: no goal yet), x_d holds. "
      "Defaults: speed 0.25 m/s, acceleration 1 m/s^2, angular_speed 1 rad/s, angular_acceleration 4 "
      "rad/s^2. The task must be periodic. See docs/modules/cartesian_interp.md.";

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_var("x_goal", Dim::fixed(6), "goal tool pose [x y z rx ry rz], m and rad (NaN: none yet)");
    d.in_var("x_m", Dim::fixed(6), "measured tool pose, m and rad: where the motion starts");
    d.out_var("x_d", Dim::fixed(6), "desired tool pose, m and rad");
    d.out_var("dx_d", Dim::fixed(6), "desired tool velocity [vx vy vz wx wy wz], m/s and rad/s");
    const Limits defaults;
    d.param("speed", defaults.speed, "m/s", "highest speed of the tool point");
    d.param("acceleration", defaults.acceleration, "m/s^2", "highest acceleration of the tool point");
    d.param("angular_speed", defaults.angular_speed, "rad/s", "highest angular speed of the tool");
    d.param("angular_acceleration", defaults.angular_acceleration, "rad/s^2", "highest angular acceleration");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    limits_.speed = p.number("speed", limits_.speed);
    limits_.acceleration = p.number("acceleration", limits_.acceleration);
    limits_.angular_speed = p.number("angular_speed", limits_.angular_speed);
    limits_.angular_acceleration = p.number("angular_acceleration", limits_.angular_acceleration);
    for (const double limit :
         {limits_.speed, limits_.acceleration, limits_.angular_speed, limits_.angular_acceleration})
      if (!(limit > 0.0 && limit < 1e6)) return Status::fail("cartesian_interp: every limit must be > 0");
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
    motion_.step(has_goal ? pose_of(x_goal_.values()) : motion_.pose(), limits_, dt_);
    publish();
    return Status::ok();
  }

 private:
  // Where the tool is, at rest; false while nothing has measured it.
  bool start_from_measurement() noexcept {
    if (!x_m_.has_data() || !finite_pose(x_m_.values())) return false;
    motion_.reset(pose_of(x_m_.values()));
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
