#pragma once
// A simulated robot arm (MuJoCo) for the robot interfaces' resource port: joint torques in (or,
// in position mode, joint positions for the arm's own servo), measured joint positions and
// velocities out, on simulated time that advances only when the caller steps it. A real arm's
// driver would sit in the same place behind the same module.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/core/result.hpp"
#include "chimera/sim/gaussian_noise.hpp"

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

/// How the arm's motors are driven.
enum class Drive {
  kTorque,    // the torques given by set_torque
  kPosition,  // the arm's own position servo, run at every physics step, toward set_position_target
};

/// The position servo's gains and the limits of its reference motion, ndof entries each.
struct ServoGains {
  std::vector<double> kp;                // N*m/rad
  std::vector<double> kd;                // N*m*s/rad
  std::vector<double> max_speed;         // rad/s: fastest motion of the reference toward a target
  std::vector<double> max_acceleration;  // rad/s^2
};

/// Bandwidth and reference speed limit of the servo a freshly loaded arm has.
inline constexpr double kDefaultServoBandwidthHz = 10.0;
inline constexpr double kDefaultServoMaxSpeed = 3.0;  // rad/s

/// The pose of a site of the model in the world frame; rotation row-major (site axes as columns).
struct SitePose {
  std::array<double, 3> position{};
  std::array<double, 9> rotation{};
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

  /// Lower and upper limits of joint i's range (rad, or m for a slide); +-infinity if unlimited.
  /// Real-time safe.
  [[nodiscard]] double joint_min(int i) const noexcept;
  [[nodiscard]] double joint_max(int i) const noexcept;

  /// How the motors are driven (kTorque after load). Entering kPosition starts the servo's
  /// reference at the arm's present position, at rest, and aims it there until a target is set:
  /// the arm is held where it is. Real-time safe.
  void set_drive(Drive drive) noexcept;
  [[nodiscard]] Drive drive() const noexcept { return drive_; }
  /// Aims the position servo at where the arm is now, its reference at rest there: the arm
  /// brakes and stays put (the locally stable mode of a robot interface). Real-time safe.
  void hold() noexcept;
  /// The joint positions the position servo moves the arm to, clamped into the joint ranges;
  /// missing entries keep their target, a NaN entry is ignored. Called once a period with a
  /// moving target, it also estimates the target's speed, so that the reference follows it
  /// without lag. Real-time safe.
  void set_position_target(std::span<const double> q) noexcept;
  [[nodiscard]] std::span<const double> position_target() const noexcept { return target_; }
  /// Where the servo's reference is, and how fast it moves: toward the target, as fast as
  /// max_speed and max_acceleration allow while still able to stop on it (an online trajectory).
  [[nodiscard]] std::span<const double> position_reference() const noexcept { return reference_; }
  [[nodiscard]] std::span<const double> reference_speed() const noexcept { return reference_speed_; }
  /// Gains for a critically damped servo of bandwidth `hz` on every joint: w = 2 pi hz,
  /// kp = m w^2, kd = 2 m w, with m the joint's own inertia (the diagonal of the joint-space
  /// inertia matrix, motor armature included) in the model's reference posture; max_acceleration
  /// is half the joint's torque limit over that inertia, so that the other half is left for
  /// gravity and the pull of the other links. Not real-time safe.
  [[nodiscard]] ServoGains servo_gains(double bandwidth_hz, double max_speed) const;
  /// Replaces the servo's gains (ndof entries each; kp, kd >= 0, max_speed and max_acceleration
  /// > 0). A new arm has servo_gains(kDefaultServoBandwidthHz, kDefaultServoMaxSpeed). Not
  /// real-time safe.
  Result<void> set_servo_gains(ServoGains gains);
  [[nodiscard]] const ServoGains& servo() const noexcept { return gains_; }

  /// Advances simulated time by dt_ns: as many MuJoCo steps as fit, the remainder carried to the
  /// next call, so that many calls never drift from the sum of their dt. In position mode the
  /// servo runs once a MuJoCo step, on the true state: with r the reference,
  ///   torque = M(q) r'' + bias(q, q') - damping(q') + kp (r - q) + kd (r' - q'),
  /// the model's inverse dynamics of the reference motion (inertia, gravity, Coriolis, joint
  /// damping) plus a PD on what is left, clamped to the motor limits. Real-time safe (MuJoCo works
  /// in the arena it allocated at load).
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

  /// The index of the model's site `name` (such as arm6.xml's "tool"). Not real-time safe.
  [[nodiscard]] Result<int> find_site(std::string_view name) const;
  /// The true pose of a site at the present joint positions (no sensor noise), from MuJoCo's own
  /// forward kinematics. Real-time safe.
  [[nodiscard]] SitePose site_pose(int site) noexcept;

 private:
  ArmSim() = default;
  void measure() noexcept;
  void servo_control() noexcept;
  void plan_reference(std::size_t k, double dt, bool target_moving) noexcept;

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
  GaussianNoise gaussian_;
  Drive drive_ = Drive::kTorque;
  ServoGains gains_;
  // The servo's state, sized at load and never grown.
  std::vector<double> target_;
  std::vector<double> target_speed_;  // estimated from successive targets
  std::int64_t target_step_ = 0;      // steps_ when the target was last set
  std::int64_t target_interval_ = 1;  // steps between the last two targets
  std::vector<double> reference_;
  std::vector<double> reference_speed_;
  std::vector<double> reference_acceleration_;
  std::vector<double> feedforward_;        // M(q) times the reference acceleration
  std::vector<double> reference_inertia_;  // joint-space inertia diagonal in the reference posture
};

}  // namespace chimera::sim
