// robot_position: the position-mode robot interface of the paper's Figures 8 and 9. Like a real
// position-controlled arm, the simulated arm behind its resource port closes its own servo loop,
// at every physics step; the interface hands it the desired joint positions once a period.

#include "module_docs/robot_position.hpp"

#include <cmath>
#include <string>

#include "chimera/module/registry.hpp"
#include "support/module_support.hpp"
#include "support/simulated_arm.hpp"

namespace chimera::modules {
namespace {

class RobotPosition final : public Module {
 public:
  static constexpr const char* kName = "robot_position";
  static constexpr const char* kSummary = docs::robot_position::kSummary;
  static constexpr const char* kDoc = docs::robot_position::kText;

  static void declare(Declarations& d, const Params& p) {
    const std::uint32_t n = robot_ndof(p);
    d.in_var("theta_d", Dim::fixed(n), "desired joint positions, rad (clamped to the joint ranges)");
    declare_simulated_arm(d, p);
    d.param("bandwidth", sim::kDefaultServoBandwidthHz, "Hz", "bandwidth of the arm's position servo").greater_than(0);
    d.param("max_speed", Vector(n, sim::kDefaultServoMaxSpeed), "rad/s",
            "fastest joint motion toward theta_d (one per joint, or one for all)");
    d.param("max_acceleration", Vector{}, "rad/s^2",
            "highest joint acceleration (one per joint, or one for all); empty: half the joint's torque limit over "
            "its inertia");
  }

 protected:
  Status init(InitContext& ctx) override {
    if (Status s = arm_.init(ctx, kName); !s.is_ok() || ctx.failed()) return s;
    sim::ArmSim& sim = arm_.sim();
    const auto n = static_cast<std::size_t>(sim.ndof());
    const Params& p = ctx.params();
    const double bandwidth = p.number("bandwidth", sim::kDefaultServoBandwidthHz);
    if (!(bandwidth > 0.0) || !std::isfinite(bandwidth))
      return Status::fail("robot_position: parameter bandwidth must be > 0 Hz");
    sim::ServoGains gains = sim.servo_gains(bandwidth, sim::kDefaultServoMaxSpeed);
    gains.max_speed = per_joint(p, "max_speed", Vector(n, sim::kDefaultServoMaxSpeed), n);
    if (p.has("max_acceleration") && !p.vector("max_acceleration").empty())
      gains.max_acceleration = per_joint(p, "max_acceleration", {}, n);
    if (gains.max_speed.empty() || gains.max_acceleration.empty())
      return Status::fail("robot_position: max_speed and max_acceleration need ndof (or 1) values");
    if (auto set = sim.set_servo_gains(std::move(gains)); !set)
      return Status::fail(intern("robot_position: " + set.error().message));

    theta_d_ = ctx.in<double>("theta_d");
    if (!ctx.failed() && theta_d_.size() != n)
      return Status::fail("robot_position: port sizes differ from parameter ndof");
    sim.set_drive(sim::Drive::kPosition);  // the arm holds its initial posture
    return Status::ok();
  }

  Status on() override {
    arm_.sim().hold();
    holding_ = false;
    arm_.publish();
    return Status::ok();
  }

  Status cycle() override {
    // Paper 3.4: while the configuration may be illegal, ignore theta_d and hold where the arm
    // was when the flag rose.
    if (arm_.illegal_configuration()) {
      if (!holding_) arm_.sim().hold();
      holding_ = true;
    } else {
      holding_ = false;
      if (theta_d_.has_data()) arm_.sim().set_position_target(theta_d_.values());
    }
    return arm_.step();
  }

  Status off() override {
    arm_.sim().hold();  // a position-controlled arm left alone stays where it is
    return Status::ok();
  }

  // A late cycle of the simulated arm is only late (SimulatedArm::judge_fault, late_limit).
  Status error() override { return arm_.judge_fault(); }

  Status kill() override {
    arm_.kill();
    return Status::ok();
  }

  Status clear() override {
    arm_.restore();
    if (arm_.sim().drive() == sim::Drive::kPosition) arm_.sim().hold();
    return Status::ok();
  }

 private:
  SimulatedArm arm_;
  In<double> theta_d_;
  bool holding_ = false;
};

CHIMERA_REGISTER_MODULE(RobotPosition);

}  // namespace
}  // namespace chimera::modules
