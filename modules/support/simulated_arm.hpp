#pragma once
// What the two robot interfaces (robot_torque, robot_position) share: the simulated arm behind
// their resource port, its parameters, the measured joint state they publish, the out-const ndof,
// and the paper's locally stable mode while the illegal-configuration flag is raised (3.4).

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "chimera/module/fault_tolerance.hpp"
#include "chimera/module/module.hpp"
#include "chimera/sim/arm_sim.hpp"

namespace chimera::modules {

/// The ndof parameter as a port size: the interfaces size their own ports from it, since ndof is
/// their out-const and the resolver sizes a task's ports only from its in-consts.
std::uint32_t robot_ndof(const Params& p);

/// Declares theta_m, dtheta_m, the out-const ndof and the parameters ndof, model, noise_std,
/// seed, initial and late_limit. Not real-time safe.
void declare_simulated_arm(Declarations& d, const Params& p);

/// The arm behind a robot interface's resource port, stepped by the task's period.
class SimulatedArm {
 public:
  /// Loads the model named by the parameters, puts the arm at `initial`, binds theta_m, dtheta_m
  /// and ndof and publishes them. `module` names the module in messages. Not real-time safe.
  Status init(InitContext& ctx, const std::string& module);
  /// Frees the simulation. Not real-time safe.
  void kill() { sim_.reset(); }

  [[nodiscard]] sim::ArmSim& sim() noexcept { return *sim_; }
  /// Advances the arm by one period and publishes its measured state; fails once the simulation
  /// diverged. Real-time safe.
  Status step() noexcept;
  /// Publishes the measured joint state. Real-time safe.
  void publish() noexcept;
  /// After a diverged simulation: the arm back at `initial`, at rest. Real-time safe.
  void restore() noexcept;

  /// Whether the subsystem's illegal-configuration flag is raised: then the interface ignores its
  /// inputs and holds the arm (paper 3.4). Real-time safe.
  [[nodiscard]] bool illegal_configuration() const noexcept { return flags_->illegal_configuration(); }

  /// The interface's error(): the simulated arm steps by the period whenever the cycle runs, so a
  /// late cycle is only late; it recovers from timing faults unless late_limit of them come in a
  /// row (a real arm's driver would be stricter). Any other fault stands. Real-time safe.
  Status judge_fault() noexcept { return tolerance_.judge(*timing_); }

 private:
  std::unique_ptr<sim::ArmSim> sim_;
  const SubsystemFlags* flags_ = nullptr;
  Out<double> theta_m_;
  Out<double> dtheta_m_;
  std::int64_t period_ns_ = 0;
  Vector initial_;
  const CycleTiming* timing_ = nullptr;
  TimingFaultTolerance tolerance_{100};
  const char* diverged_ = "the simulation diverged (NaN or runaway state)";
};

}  // namespace chimera::modules
