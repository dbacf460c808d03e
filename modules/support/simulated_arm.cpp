#include "support/simulated_arm.hpp"

#include <cmath>
#include <utility>

#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

constexpr double kDefaultNdof = 6.0;
constexpr double kDefaultLateLimit = 100;
constexpr int kMaxNdof = 64;

}  // namespace

std::uint32_t robot_ndof(const Params& p) {
  const double n = p.number("ndof", kDefaultNdof);
  if (!(n >= 1.0) || n > kMaxNdof) return static_cast<std::uint32_t>(kDefaultNdof);
  return static_cast<std::uint32_t>(std::lround(n));
}

void declare_simulated_arm(Declarations& d, const Params& p) {
  const std::uint32_t n = robot_ndof(p);
  d.out_var("theta_m", Dim::fixed(n), "measured joint positions, rad");
  d.out_var("dtheta_m", Dim::fixed(n), "measured joint velocities, rad/s");
  d.out_const("ndof", {static_cast<double>(n)}, "degrees of freedom of the arm");
  d.param("ndof", kDefaultNdof, "", "number of joints; must match the model").whole().at_least(1).at_most(64);
  d.param("model", std::string(), "", "MJCF model file; empty: the shipped arm6.xml");
  d.param("noise_std", 0.0, "rad", "standard deviation of Gaussian noise on theta_m").at_least(0);
  d.param("seed", 1.0, "", "seed of the measurement noise (runs repeat exactly)");
  d.param("initial", Vector(n, 0.0), "rad", "joint positions at init");
  d.param("late_limit", kDefaultLateLimit, "cycles",
          "timing faults (late cycles, budget overruns) in a row that error() recovers from before ERROR")
      .whole()
      .at_least(1);
  d.resource("MuJoCo simulation of a PUMA 560-like 6-joint arm (sim/models/arm6.xml), stepped by the task's period");
}

Status SimulatedArm::init(InitContext& ctx, const std::string& module) {
  const Params& p = ctx.params();
  const double ndof_param = p.number("ndof", kDefaultNdof);
  if (!(ndof_param >= 1.0) || ndof_param > kMaxNdof || ndof_param != std::floor(ndof_param))
    return Status::fail(intern(module + ": parameter ndof must be a whole number from 1 to 64"));
  const auto n = static_cast<int>(ndof_param);
  period_ns_ = ctx.timing().period_ns;
  if (period_ns_ <= 0)
    return Status::fail(intern(module + ": the task must be periodic (its period steps the simulation)"));
  flags_ = &ctx.flags();
  timing_ = &ctx.timing();
  const double late_limit = p.number("late_limit", kDefaultLateLimit);
  if (!(late_limit >= 1.0) || late_limit != std::floor(late_limit))
    return Status::fail(intern(module + ": parameter late_limit must be a whole number of cycles >= 1"));
  tolerance_ = TimingFaultTolerance(static_cast<std::uint64_t>(late_limit));
  diverged_ = intern(module + ": the simulation diverged (NaN or runaway state)");

  const double noise_std = p.number("noise_std", 0.0);
  if (!(noise_std >= 0.0)) return Status::fail(intern(module + ": parameter noise_std must be >= 0 rad"));
  sim::SensorNoise noise;
  noise.position_std = noise_std;
  noise.seed = static_cast<std::uint64_t>(std::llround(std::fabs(p.number("seed", 1.0))));
  auto loaded = sim::ArmSim::load(p.text("model"), noise);
  if (!loaded) return Status::fail(intern(module + ": " + loaded.error().message));
  sim_ = std::move(loaded).value();
  if (sim_->ndof() != n)
    return Status::fail(intern(module + ": model '" + sim_->path() + "' has " + std::to_string(sim_->ndof()) +
                               " joints but parameter ndof is " + std::to_string(n)));

  initial_ = p.vector("initial", Vector(static_cast<std::size_t>(n), 0.0));
  if (!initial_.empty() && initial_.size() != static_cast<std::size_t>(n))
    return Status::fail(intern(module + ": parameter initial has " + std::to_string(initial_.size()) +
                               " entries, the arm has " + std::to_string(n) + " joints"));
  sim_->set_state(initial_, {});

  theta_m_ = ctx.out<double>("theta_m");
  dtheta_m_ = ctx.out<double>("dtheta_m");
  Out<double> ndof_out = ctx.out<double>("ndof");
  // An unbound view already fails init with a message naming the port (InitContext's rule).
  if (ctx.failed()) return Status::ok();
  if (theta_m_.size() != static_cast<std::size_t>(n))
    return Status::fail(intern(module + ": port sizes differ from parameter ndof"));
  ndof_out[0] = n;
  publish();
  return Status::ok();
}

Status SimulatedArm::step() noexcept {
  sim_->step(period_ns_);
  publish();
  return sim_->diverged() ? Status::fail(diverged_) : Status::ok();
}

void SimulatedArm::publish() noexcept {
  const auto q = sim_->positions();
  const auto qd = sim_->velocities();
  for (std::size_t i = 0; i < theta_m_.size(); ++i) {
    theta_m_[i] = q[i];
    dtheta_m_[i] = qd[i];
  }
}

void SimulatedArm::restore() noexcept {
  if (!sim_ || !sim_->diverged()) return;
  sim_->reset();
  sim_->set_state(initial_, {});
  publish();
}

}  // namespace chimera::modules
