// robot_torque: the torque-mode robot interface of the paper's Figure 4. Its resource port is a
// MuJoCo simulation of a 6-joint arm; a real arm's driver would take the same place.

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "chimera/module/registry.hpp"
#include "chimera/sim/arm_sim.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

constexpr double kDefaultNdof = 6.0;
constexpr int kMaxNdof = 64;

// The port sizes come from the ndof parameter, because ndof is this module's out-const and the
// resolver only sizes ports from a task's own in-consts.
std::uint32_t ndof_of(const Params& p) {
  const double n = p.number("ndof", kDefaultNdof);
  if (!(n >= 1.0) || n > kMaxNdof) return static_cast<std::uint32_t>(kDefaultNdof);
  return static_cast<std::uint32_t>(std::lround(n));
}

class RobotTorque final : public Module {
 public:
  static constexpr const char* kName = "robot_torque";
  static constexpr const char* kSummary = "Torque-mode robot interface: joint torques to a simulated 6-joint arm";
  static constexpr const char* kDoc =
      "The torque-mode robot interface of the paper's Figure 4. Each cycle it applies the reference "
      "torques tau_r (N*m, zero until some task has written them) to the arm, advances the arm by "
      "one period of its task, and publishes the measured joint positions theta_m (rad) and "
      "velocities dtheta_m (rad/s); it also publishes them at init and on, so consumers start from "
      "where the arm really is. Its resource port is a MuJoCo simulation of a PUMA 560-like arm "
      "(sim/models/arm6.xml: waist, shoulder, elbow and a 3-axis wrist, torque limits "
      "150/150/80/20/20/20 N*m, 1 ms physics step); simulated time advances only with the cycles, so "
      "the arm runs deterministically on the virtual clock. The out-const ndof tells the other "
      "modules how many joints there are. Parameters: ndof (default 6; init fails if the model has "
      "another number of joints), model (MJCF file, default \"\" = the shipped arm6.xml, looked up "
      "on $CHIMERA_MODEL_PATH, then the source tree, then share/chimera/models), noise_std (rad, "
      "default 0: standard deviation of Gaussian noise on theta_m), seed (default 1: the noise's "
      "fixed seed), initial (rad, default zeros: the joint positions at init). The task must be "
      "periodic: its period is the simulation's step. See docs/modules/robot_torque.md.";

  static void declare(Declarations& d, const Params& p) {
    const std::uint32_t n = ndof_of(p);
    d.in_var("tau_r", Dim::fixed(n), "reference joint torques, N*m (clamped to the arm's limits)");
    d.out_var("theta_m", Dim::fixed(n), "measured joint positions, rad");
    d.out_var("dtheta_m", Dim::fixed(n), "measured joint velocities, rad/s");
    d.out_const("ndof", {static_cast<double>(n)}, "degrees of freedom of the arm");
    d.param("ndof", kDefaultNdof, "", "number of joints; must match the model");
    d.param("model", std::string(), "", "MJCF model file; empty: the shipped arm6.xml");
    d.param("noise_std", 0.0, "rad", "standard deviation of Gaussian noise on theta_m");
    d.param("seed", 1.0, "", "seed of the measurement noise (runs repeat exactly)");
    d.param("initial", Vector(n, 0.0), "rad", "joint positions at init");
    d.resource("MuJoCo simulation of a PUMA 560-like 6-joint arm (sim/models/arm6.xml), stepped by the task's period");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    const double ndof_param = p.number("ndof", kDefaultNdof);
    if (!(ndof_param >= 1.0) || ndof_param > kMaxNdof || ndof_param != std::floor(ndof_param))
      return Status::fail("robot_torque: parameter ndof must be a whole number from 1 to 64");
    const auto n = static_cast<int>(ndof_param);
    period_ns_ = ctx.timing().period_ns;
    if (period_ns_ <= 0)
      return Status::fail("robot_torque: the task must be periodic (its period steps the simulation)");

    const double noise_std = p.number("noise_std", 0.0);
    if (!(noise_std >= 0.0)) return Status::fail("robot_torque: parameter noise_std must be >= 0 rad");
    sim::SensorNoise noise;
    noise.position_std = noise_std;
    noise.seed = static_cast<std::uint64_t>(std::llround(std::fabs(p.number("seed", 1.0))));
    auto loaded = sim::ArmSim::load(p.text("model"), noise);
    if (!loaded) return Status::fail(intern("robot_torque: " + loaded.error().message));
    sim_ = std::move(loaded).value();
    if (sim_->ndof() != n)
      return Status::fail(intern("robot_torque: model '" + sim_->path() + "' has " + std::to_string(sim_->ndof()) +
                                 " joints but parameter ndof is " + std::to_string(n)));

    initial_ = p.vector("initial", Vector(static_cast<std::size_t>(n), 0.0));
    if (!initial_.empty() && initial_.size() != static_cast<std::size_t>(n))
      return Status::fail(intern("robot_torque: parameter initial has " + std::to_string(initial_.size()) +
                                 " entries, the arm has " + std::to_string(n) + " joints"));
    sim_->set_state(initial_, {});

    tau_r_ = ctx.in<double>("tau_r");
    theta_m_ = ctx.out<double>("theta_m");
    dtheta_m_ = ctx.out<double>("dtheta_m");
    Out<double> ndof_out = ctx.out<double>("ndof");
    // An unbound view already fails init with a message naming the port (InitContext's rule).
    if (ctx.failed()) return Status::ok();
    if (theta_m_.size() != static_cast<std::size_t>(n) || tau_r_.size() != static_cast<std::size_t>(n))
      return Status::fail("robot_torque: port sizes differ from parameter ndof");
    ndof_out[0] = n;
    publish();
    return Status::ok();
  }

  Status on() override {
    sim_->set_torque({});  // nothing is applied until a controller speaks
    publish();
    return Status::ok();
  }

  Status cycle() override {
    sim_->set_torque(tau_r_.has_data() ? tau_r_.values() : std::span<const double>());
    sim_->step(period_ns_);
    publish();
    if (sim_->diverged()) return Status::fail("robot_torque: the simulation diverged (NaN or runaway state)");
    return Status::ok();
  }

  Status off() override {
    sim_->set_torque({});  // a switched-off interface must not leave torque applied
    return Status::ok();
  }

  Status kill() override {
    sim_.reset();
    return Status::ok();
  }

  // The only fault of our own is a diverged simulation; clearing puts the arm back at rest where
  // it was first created.
  Status clear() override {
    if (sim_ && sim_->diverged()) {
      sim_->reset();
      sim_->set_state(initial_, {});
      publish();
    }
    return Status::ok();
  }

 private:
  void publish() noexcept {
    const auto q = sim_->positions();
    const auto qd = sim_->velocities();
    for (std::size_t i = 0; i < theta_m_.size(); ++i) {
      theta_m_[i] = q[i];
      dtheta_m_[i] = qd[i];
    }
  }

  std::unique_ptr<sim::ArmSim> sim_;
  In<double> tau_r_;
  Out<double> theta_m_;
  Out<double> dtheta_m_;
  std::int64_t period_ns_ = 0;
  Vector initial_;
};

CHIMERA_REGISTER_MODULE(RobotTorque);

}  // namespace
}  // namespace chimera::modules
