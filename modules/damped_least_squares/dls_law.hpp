#pragma once
// The damped_least_squares module's law, apart from the framework so that tests can use it
// directly: resolved-rate control through a damped least-squares inverse of the Jacobian whose
// damping grows as the arm nears a singularity.

#include <algorithm>
#include <cmath>
#include <span>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

#include "kinematics/arm_chain.hpp"
#include "kinematics/pose.hpp"

namespace chimera::modules {

struct DlsSettings {
  double gain = 10.0;                      // 1/s: twist commanded per unit of pose error
  double max_linear_speed = 0.5;           // m/s: the commanded tool speed is clipped to this
  double max_angular_speed = 1.5;          // rad/s
  double max_damping = 0.05;               // lambda_max, in m (and rad) like the Jacobian's entries
  double manipulability_threshold = 0.04;  // w_0: below it the damping sets in
};

/// Wampler and Leifer (1988): with the commanded twist v = gain * pose_error(x_d, x_m), clipped
/// to the speed limits,
///     dtheta = J^T (J J^T + lambda^2 I)^-1 v,
/// the joint velocity that minimises |J dtheta - v|^2 + lambda^2 |dtheta|^2. Far from a
/// singularity lambda = 0 and this is the exact inverse; near one the damping bounds the joint
/// speed, |dtheta| <= |v| / (2 lambda), at the price of a tracking error along the lost direction.
/// The damping follows the manipulability w = sqrt(det(J J^T)) (Yoshikawa 1985) as Nakamura and
/// Hanafusa (1986) proposed:
///     lambda^2 = max_damping^2 (1 - (w / w_0)^2)  for w < w_0,  0 otherwise.
class DlsLaw {
 public:
  void configure(const DlsSettings& settings) noexcept { s_ = settings; }
  [[nodiscard]] const DlsSettings& settings() const noexcept { return s_; }

  /// The damping for manipulability w. Real-time safe.
  [[nodiscard]] double damping_squared(double w) const noexcept {
    if (w >= s_.manipulability_threshold) return 0.0;
    const double ratio = w / s_.manipulability_threshold;
    return s_.max_damping * s_.max_damping * (1.0 - ratio * ratio);
  }

  /// The commanded twist: gain times the pose error, each part clipped to its speed limit.
  /// Real-time safe.
  [[nodiscard]] kinematics::Vector6 twist(const kinematics::Pose& desired,
                                          const kinematics::Pose& measured) const noexcept {
    kinematics::Vector6 v = s_.gain * kinematics::pose_error(desired, measured);
    const double linear = v.head<3>().norm();
    if (linear > s_.max_linear_speed) v.head<3>() *= s_.max_linear_speed / linear;
    const double angular = v.tail<3>().norm();
    if (angular > s_.max_angular_speed) v.tail<3>() *= s_.max_angular_speed / angular;
    return v;
  }

  /// Joint velocities for the twist v at Jacobian J (6 x n), written to dtheta (n entries).
  /// Real-time safe: fixed-capacity matrices only.
  void update(const kinematics::JacobianMatrix& jacobian, const kinematics::Vector6& v,
              std::span<double> dtheta) noexcept {
    const Eigen::Matrix<double, 6, 6> jjt = jacobian * jacobian.transpose();
    manipulability_ = std::sqrt(std::max(jjt.determinant(), 0.0));
    damping_squared_ = damping_squared(manipulability_);
    const Eigen::Matrix<double, 6, 6> a = jjt + damping_squared_ * Eigen::Matrix<double, 6, 6>::Identity();
    const kinematics::Vector6 weights = a.ldlt().solve(v);
    kinematics::JointVector rates = kinematics::JointVector::Zero(jacobian.cols());
    rates.noalias() = jacobian.transpose() * weights;
    for (Eigen::Index i = 0; i < rates.size(); ++i) dtheta[static_cast<std::size_t>(i)] = rates[i];
  }

  /// What the last update found. Real-time safe.
  [[nodiscard]] double manipulability() const noexcept { return manipulability_; }
  [[nodiscard]] double damping() const noexcept { return std::sqrt(damping_squared_); }

 private:
  DlsSettings s_;
  double manipulability_ = 0.0;
  double damping_squared_ = 0.0;
};

}  // namespace chimera::modules
