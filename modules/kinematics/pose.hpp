#pragma once
// Poses as the kinematics modules exchange them through state variables (x_m, x_d) and the
// algebra the modules need on them. A pose is 6 numbers:
//
//   [ x, y, z, rx, ry, rz ]
//
// the position of the tool point in the arm's base frame (m), then the tool's orientation as a
// rotation vector in the base frame (rad): the unit axis of the rotation from the base frame to
// the tool frame times its angle, with the angle in [0, pi] (the form of Universal Robots' pose,
// p[x, y, z, rx, ry, rz]). A rotation vector has no gimbal lock; it jumps only where the angle
// passes pi (where r and -r name the same rotation), so the modules never subtract rotation
// vectors: they convert to rotation matrices, which are continuous everywhere.
//
// Everything here works on fixed-size Eigen types: no allocation, real-time safe.

#include <cmath>
#include <cstddef>
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace chimera::kinematics {

using Vector6 = Eigen::Matrix<double, 6, 1>;

/// The rotation of rotation vector r (Rodrigues' formula). Real-time safe.
inline Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& r) noexcept {
  const double angle = r.norm();
  if (angle < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
}

/// The rotation vector of R, angle in [0, pi] (through a quaternion, which stays accurate near
/// 0 and pi where the trace formula does not). Real-time safe.
inline Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& rotation) noexcept {
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(rotation).normalized());
  return aa.angle() * aa.axis();
}

/// A rigid pose: position (m) and rotation matrix, both in the base frame.
struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
};

/// The pose held in 6 numbers [x y z rx ry rz]. Real-time safe; x must have 6 elements.
inline Pose pose_from(std::span<const double> x) noexcept {
  Pose p;
  p.position = Eigen::Vector3d(x[0], x[1], x[2]);
  p.rotation = rotation_from_vector(Eigen::Vector3d(x[3], x[4], x[5]));
  return p;
}

/// Writes `pose` as 6 numbers [x y z rx ry rz]. Real-time safe; x must have 6 elements.
inline void write_pose(const Pose& pose, std::span<double> x) noexcept {
  const Eigen::Vector3d r = rotation_vector(pose.rotation);
  for (std::size_t i = 0; i < 3; ++i) {
    x[i] = pose.position[static_cast<Eigen::Index>(i)];
    x[i + 3] = r[static_cast<Eigen::Index>(i)];
  }
}

/// The error that takes `actual` to `desired`: [p_d - p_a; rotation vector of R_d R_a^T], in the
/// base frame. Its angular part is the rotation about base axes (through the tool point) that
/// turns the actual orientation into the desired one, so that, divided by a time, it is the
/// twist a geometric Jacobian maps joint velocities to. Real-time safe.
inline Vector6 pose_error(const Pose& desired, const Pose& actual) noexcept {
  Vector6 e;
  e.head<3>() = desired.position - actual.position;
  e.tail<3>() = rotation_vector(desired.rotation * actual.rotation.transpose());
  return e;
}

/// `pose` moved by the small displacement d = [dp; dr]: p + dp, and R turned by dr about the
/// base axes. The inverse of pose_error: pose_error(displace(a, d), a) == d. Real-time safe.
inline Pose displace(const Pose& pose, const Vector6& d) noexcept {
  Pose out;
  out.position = pose.position + d.head<3>();
  out.rotation = rotation_from_vector(d.tail<3>()) * pose.rotation;
  return out;
}

/// The pose a fraction f of the way from `from` to `to`: positions interpolated on the line,
/// orientations on the shortest rotation between them. f = 0 gives `from`, 1 gives `to`.
/// Real-time safe.
inline Pose step_toward(const Pose& from, const Pose& to, double f) noexcept {
  return displace(from, f * pose_error(to, from));
}

/// Position and orientation parts of an error, as the norms tests and solvers compare.
inline double position_norm(const Vector6& e) noexcept { return e.head<3>().norm(); }
inline double orientation_norm(const Vector6& e) noexcept { return e.tail<3>().norm(); }

}  // namespace chimera::kinematics
