#pragma once
// A simulated robot arm (MuJoCo) for the robot interfaces' resource port: joint torques in,
// measured joint positions and velocities out, on simulated time that advances only when the
// caller steps it. A real arm's driver would sit in the same place behind the same module.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/core/result.hpp"

struct mjModel_;
struct mjData_;

namespace chimera::sim {

/// The name of the model shipped with Chimera: a PUMA 560-like 6-joint arm.
inline constexpr std::string_view kDefaultModel = "arm6.xml";

/// Directories searched for a model given by a bare or relative name, in order: each entry of
/// the environment variable CHIMERA_MODEL_PATH (':'-separated), the source tree's sim/models
/// (builds run from the tree), the installed share/chimera/models. Not real-time safe.
std::vector<std::string> model_search_path();

/// Resolves `name` to a readable file: an existing path as given, else the first match in
/// model_search_path(). An empty name means kDefaultModel. Not real-time safe.
Result<std::string> find_model(std::string_view name);

/// Measurement noise added to what positions() and velocities() report (never to the dynamics).
struct SensorNoise {
  double position_std = 0.0;  // rad (or m for a slide joint)
  double velocity_std = 0.0;  // rad/s
  std::uint64_t seed = 1;     // fixed seed: the same run gives the same noise
};

/// One arm: a MuJoCo model whose actuator i is a motor on joint i, one degree of freedom each.
class ArmSim {
 public:
  /// Loads an MJCF file (a path, or a name found by find_model). Fails with the path and
  /// MuJoCo's message, or when the model is not one motor per single-dof joint. Not real-time safe.
  static Result<std::unique_ptr<ArmSim>> load(std::string_view path, SensorNoise noise = {});
  ~ArmSim();
  ArmSim(const ArmSim&) = delete;
  ArmSim& operator=(const ArmSim&) = delete;

  /// Degrees of freedom (= joints = actuators). Real-time safe.
  [[nodiscard]] int ndof() const noexcept { return ndof_; }
  /// The file the model came from.
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  /// MuJoCo's integration step, in ns.
  [[nodiscard]] std::int64_t timestep_ns() const noexcept { return timestep_ns_; }

  /// Joint torques to apply from now on, clamped to each actuator's range; missing entries are
  /// zero, extra ones ignored. Real-time safe.
  void set_torque(std::span<const double> tau) noexcept;
  /// The torques being applied (after clamping). Real-time safe.
  [[nodiscard]] std::span<const double> torque() const noexcept;
  /// Lower and upper torque limits of joint i. Real-time safe.
  [[nodiscard]] double torque_min(int i) const noexcept;
  [[nodiscard]] double torque_max(int i) const noexcept;

  /// Advances simulated time by dt_ns: as many MuJoCo steps as fit, the remainder carried to the
  /// next call, so that many calls never drift from the sum of their dt. Real-time safe (MuJoCo
  /// works in the arena it allocated at load).
  void step(std::int64_t dt_ns) noexcept;
  /// Measured joint positions and velocities (with the sensor noise, if any). Real-time safe.
  [[nodiscard]] std::span<const double> positions() const noexcept { return q_meas_; }
  [[nodiscard]] std::span<const double> velocities() const noexcept { return qd_meas_; }
  /// Simulated time: whole MuJoCo steps taken since load or reset, exact in ns.
  [[nodiscard]] std::int64_t time_ns() const noexcept { return steps_ * timestep_ns_; }
  [[nodiscard]] double time_s() const noexcept { return static_cast<double>(time_ns()) * 1e-9; }
  /// Whether MuJoCo met a NaN or a runaway value and reset itself since load or reset.
  [[nodiscard]] bool diverged() const noexcept;

  /// Puts the arm at positions q and velocities qd (missing entries zero), time unchanged.
  /// Real-time safe.
  void set_state(std::span<const double> q, std::span<const double> qd) noexcept;
  /// Back to the model's initial state at time 0, zero torque, noise restarted from its seed.
  void reset() noexcept;
  /// Gravity vector in m/s^2 (the model's default is 0 0 -9.81).
  void set_gravity(const std::array<double, 3>& g) noexcept;

 private:
  ArmSim() = default;
  void measure() noexcept;
  double gaussian() noexcept;

  struct ModelDeleter {
    void operator()(mjModel_* m) const noexcept;
  };
  struct DataDeleter {
    void operator()(mjData_* d) const noexcept;
  };
  std::unique_ptr<mjModel_, ModelDeleter> model_;
  std::unique_ptr<mjData_, DataDeleter> data_;
  std::string path_;
  int ndof_ = 0;
  std::int64_t timestep_ns_ = 0;
  std::int64_t steps_ = 0;
  std::int64_t carry_ns_ = 0;  // time asked for but shorter than one MuJoCo step
  std::vector<int> qpos_adr_;  // joint i's entry in qpos, and in qvel
  std::vector<int> dof_adr_;
  std::vector<double> q_meas_;  // sized at load, never grown
  std::vector<double> qd_meas_;
  SensorNoise noise_;
  std::uint64_t rng_ = 0;
  double spare_normal_ = 0.0;  // Box-Muller yields normals in pairs
  bool has_spare_ = false;
};

}  // namespace chimera::sim
