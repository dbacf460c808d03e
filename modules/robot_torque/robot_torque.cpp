// robot_torque: the torque-mode robot interface of the paper's Figure 4. Its resource port is a
// MuJoCo simulation of a 6-joint arm; a real arm's driver would take the same place.

#include "module_docs/robot_torque.hpp"

#include <cmath>
#include <span>
#include <string>

#include "chimera/module/registry.hpp"
#include "support/module_support.hpp"
#include "support/simulated_arm.hpp"

namespace chimera::modules {
namespace {

class RobotTorque final : public Module {
 public:
  static constexpr const char* kName = "robot_torque";
  static constexpr const char* kSummary = docs::robot_torque::kSummary;
  static constexpr const char* kDoc = docs::robot_torque::kText;

  static void declare(Declarations& d, const Params& p) {
    d.in_var("tau_r", Dim::fixed(robot_ndof(p)), "reference joint torques, N*m (clamped to the arm's limits)");
    declare_simulated_arm(d, p);
    d.param("hold_bandwidth", sim::kDefaultServoBandwidthHz, "Hz",
            "bandwidth of the hold while the illegal-configuration flag is raised")
        .greater_than(0);
  }

 protected:
  Status init(InitContext& ctx) override {
    if (Status s = arm_.init(ctx, kName); !s.is_ok() || ctx.failed()) return s;
    const double bandwidth = ctx.params().number("hold_bandwidth", sim::kDefaultServoBandwidthHz);
    if (!(bandwidth > 0.0) || !std::isfinite(bandwidth))
      return ctx.refuse("hold_bandwidth", "robot_torque: parameter hold_bandwidth must be > 0 Hz");
    const sim::ServoGains hold = arm_.sim().servo_gains(bandwidth, sim::kDefaultServoMaxSpeed);
    if (auto set = arm_.sim().set_servo_gains(hold); !set)
      return Status::fail(intern("robot_torque: " + set.error().message));
    tau_r_ = ctx.in<double>("tau_r");
    if (!ctx.failed() && tau_r_.size() != static_cast<std::size_t>(arm_.sim().ndof()))
      return Status::fail("robot_torque: port sizes differ from parameter ndof");
    return Status::ok();
  }

  Status on() override {
    release();
    arm_.publish();
    return Status::ok();
  }

  Status cycle() override {
    // Paper 3.4: while the configuration may be illegal, ignore the inputs and hold still.
    if (arm_.illegal_configuration()) {
      if (arm_.sim().drive() != sim::Drive::kPosition) arm_.sim().set_drive(sim::Drive::kPosition);
    } else {
      if (arm_.sim().drive() != sim::Drive::kTorque) arm_.sim().set_drive(sim::Drive::kTorque);
      arm_.sim().set_torque(tau_r_.has_data() ? tau_r_.values() : std::span<const double>());
    }
    return arm_.step();
  }

  Status off() override {
    release();  // a switched-off interface must not leave torque applied
    return Status::ok();
  }

  // A late cycle of the simulated arm is only late (SimulatedArm::judge_fault, late_limit).
  Status error() override { return arm_.judge_fault(); }

  Status kill() override {
    arm_.kill();
    return Status::ok();
  }

  // The only fault of our own is a diverged simulation; clearing puts the arm back at rest where
  // it was first created.
  Status clear() override {
    arm_.restore();
    return Status::ok();
  }

 private:
  // Torque mode with nothing applied until a controller speaks.
  void release() noexcept {
    arm_.sim().set_drive(sim::Drive::kTorque);
    arm_.sim().set_torque({});
  }

  SimulatedArm arm_;
  In<double> tau_r_;
};

CHIMERA_REGISTER_MODULE(RobotTorque);

}  // namespace
}  // namespace chimera::modules
