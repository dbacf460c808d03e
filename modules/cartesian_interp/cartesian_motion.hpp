#pragma once
// Cartesian trajectory interpolation: a tool pose that moves toward a goal pose, which may itself
// move, along a straight line for the position and the shortest rotation for the orientation,
// each no faster and accelerating no harder than its limits, stopping on the goal without
// overshoot. Poses are those of kinematics/pose.hpp: 6 numbers [x y z rx ry rz], the position (m)
// and a rotation vector (rad), both in the arm's base frame.
//
// Fixed-size Eigen types only: no allocation; everything here is real-time safe.

#include <algorithm>
#include <cmath>
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kinematics/pose.hpp"

namespace chimera::modules::cartesian {

using Vec3 = Eigen::Vector3d;
using kinematics::Pose;

/// Whether all 6 numbers are finite: a pose that is NaN means "none yet".
inline bool finite_pose(std::span<const double> x) noexcept {
  return x.size() == 6 && std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); });
}

/// `pose` moved by dp and turned by the rotation vector dr about the base axes.
inline Pose displaced(const Pose& pose, const Vec3& dp, const Vec3& dr) noexcept {
  kinematics::Vector6 d;
  d << dp, dr;
  return kinematics::displace(pose, d);
}

/// The rotation (about the base axes) that turns `from` into `to`, as a rotation vector.
inline Vec3 rotation_error(const Eigen::Matrix3d& to, const Eigen::Matrix3d& from) noexcept {
  return kinematics::rotation_vector(to * from.transpose());
}

/// The fastest speed toward a point `distance` away from which a body whose speed may fall by
/// at most `accel` dt each step of dt still stops exactly on it. Moving at s, s - a dt, ...,
/// s - N a dt over N + 1 steps (the last of them at most a dt) covers
/// dt (N + 1) s - a dt^2 N (N + 1) / 2, so with x = distance / (a dt^2) the speed is
/// a dt (x / (N + 1) + N / 2), N the whole number with N (N + 1) / 2 < x <= (N + 1) (N + 2) / 2.
/// Within one step of the point (N = 0) that is distance / dt. Never more than `max_speed`.
inline double approach_speed(double distance, double max_speed, double accel, double dt) noexcept {
  const double x = distance / (accel * dt * dt);
  const double n = std::max(0.0, std::ceil((std::sqrt(1.0 + 8.0 * x) - 1.0) / 2.0) - 1.0);
  return std::min(max_speed, accel * dt * (x / (n + 1.0) + n / 2.0));
}

/// One 3-vector quantity (a position, or an orientation's rotation) moving toward its target.
/// `error` is target minus current. Updates `velocity`, whose change per step is at most
/// accel dt, and returns the displacement to apply this step; `arrived` tells that this step
/// ends on the target, so that the caller can put the quantity there exactly (its velocity, at
/// most accel dt then, falls to zero in the next step).
inline Vec3 step_toward(const Vec3& error, Vec3& velocity, double max_speed, double accel, double dt,
                        bool& arrived) noexcept {
  const double distance = error.norm();
  const Vec3 wanted =
      distance > 0.0 ? Vec3(error * (approach_speed(distance, max_speed, accel, dt) / distance)) : Vec3(Vec3::Zero());
  Vec3 change = wanted - velocity;
  const double most = accel * dt;
  if (change.norm() > most) change *= most / change.norm();
  velocity += change;
  // This step lands on the target, slowly enough to stop there in the next.
  arrived = (velocity * dt - error).norm() <= 1e-12 && velocity.norm() <= most;
  return velocity * dt;
}

struct Limits {
  double speed = 0.25;                // m/s
  double acceleration = 1.0;          // m/s^2
  double angular_speed = 1.0;         // rad/s
  double angular_acceleration = 4.0;  // rad/s^2
};

/// The interpolated pose and its velocity (twist [v; w] in the base frame).
class CartesianMotion {
 public:
  /// At rest at `at`.
  void reset(const Pose& at) noexcept {
    pose_ = at;
    velocity_.setZero();
    angular_velocity_.setZero();
  }

  /// One step of dt toward `goal`.
  void step(const Pose& goal, const Limits& limits, double dt) noexcept {
    bool arrived = false;
    const Vec3 move =
        step_toward(goal.position - pose_.position, velocity_, limits.speed, limits.acceleration, dt, arrived);
    pose_.position = arrived ? goal.position : Vec3(pose_.position + move);
    const Vec3 turn = step_toward(rotation_error(goal.rotation, pose_.rotation), angular_velocity_,
                                  limits.angular_speed, limits.angular_acceleration, dt, arrived);
    // Through a unit quaternion: the product of many small turns stays a rotation.
    const Eigen::Quaterniond turned(kinematics::rotation_from_vector(turn) * pose_.rotation);
    pose_.rotation = arrived ? goal.rotation : Eigen::Matrix3d(turned.normalized().toRotationMatrix());
  }

  [[nodiscard]] const Pose& pose() const noexcept { return pose_; }
  [[nodiscard]] const Vec3& velocity() const noexcept { return velocity_; }
  [[nodiscard]] const Vec3& angular_velocity() const noexcept { return angular_velocity_; }

 private:
  Pose pose_;
  Vec3 velocity_ = Vec3::Zero();
  Vec3 angular_velocity_ = Vec3::Zero();
};

}  // namespace chimera::modules::cartesian
