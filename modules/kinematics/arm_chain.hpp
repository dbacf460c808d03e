#pragma once
// The kinematic chain of an arm, read from a URDF file (urdfdom) into an Orocos KDL chain: forward
// kinematics and the geometric Jacobian of a tip link, and the joints' limits. The kinematics
// modules (fwd_kin_jacobian, inv_kin) compute through it; the shipped sim/models/arm6.urdf is the
// same arm as the MuJoCo model sim/models/arm6.xml that the robot interfaces drive.

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "chimera/core/result.hpp"
#include "kinematics/pose.hpp"

namespace KDL {  // NOLINT(readability-identifier-naming): Orocos KDL's own namespace, declared ahead
class Chain;
class ChainFkSolverPos_recursive;
class ChainJntToJacSolver;
class JntArray;
class Jacobian;
}  // namespace KDL

namespace chimera::kinematics {

/// The most joints a chain may have: the solvers' matrices are fixed-capacity, never allocated.
inline constexpr int kMaxDof = 16;

/// The geometric Jacobian, 6 x ndof: rows vx vy vz wx wy wz (linear velocity of the tip point,
/// then angular velocity, both in the base frame), one column per joint, base to tip.
using JacobianMatrix = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::ColMajor, 6, kMaxDof>;
/// A joint-space vector of up to kMaxDof entries, on the stack.
using JointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxDof, 1>;

/// The shipped arm's URDF, found like the MuJoCo models (chimera/sim/arm_sim.hpp: find_model).
inline constexpr std::string_view kDefaultUrdf = "arm6.urdf";
inline constexpr std::string_view kDefaultBaseLink = "base";
inline constexpr std::string_view kDefaultTipLink = "tool";

class ArmChain {
 public:
  /// Reads `urdf` (a path, or a name on the model search path; empty: the shipped arm6.urdf) and
  /// builds the chain of joints from link `base` to link `tip`. Fails, naming the file and the
  /// link or joint, on a file that does not parse, a tip not below the base, a joint type other
  /// than revolute, continuous, prismatic or fixed, or more than kMaxDof joints. Not real-time safe.
  static Result<std::unique_ptr<ArmChain>> load(std::string_view urdf, std::string_view base = kDefaultBaseLink,
                                                std::string_view tip = kDefaultTipLink);
  ~ArmChain();
  ArmChain(const ArmChain&) = delete;
  ArmChain& operator=(const ArmChain&) = delete;

  /// Moving joints from base to tip. Real-time safe.
  [[nodiscard]] int ndof() const noexcept { return ndof_; }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  [[nodiscard]] const std::vector<std::string>& joint_names() const noexcept { return joint_names_; }
  /// Joint limits from the URDF (rad or m; +-infinity for a continuous joint). Real-time safe.
  [[nodiscard]] std::span<const double> lower() const noexcept { return lower_; }
  [[nodiscard]] std::span<const double> upper() const noexcept { return upper_; }

  /// The pose of the tip at joint positions q (ndof entries). Real-time safe.
  [[nodiscard]] Pose forward(std::span<const double> q) noexcept;
  /// The tip's pose and geometric Jacobian at q. Real-time safe.
  void evaluate(std::span<const double> q, Pose& pose, JacobianMatrix& jacobian) noexcept;

 private:
  ArmChain();
  void set_joints(std::span<const double> q) noexcept;

  std::unique_ptr<KDL::Chain> chain_;  // the solvers refer to it: the class neither moves nor copies
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> fk_;
  std::unique_ptr<KDL::ChainJntToJacSolver> jac_solver_;
  std::unique_ptr<KDL::JntArray> q_;         // sized at load
  std::unique_ptr<KDL::Jacobian> jacobian_;  // sized at load
  std::string path_;
  std::vector<std::string> joint_names_;
  std::vector<double> lower_;
  std::vector<double> upper_;
  int ndof_ = 0;
};

}  // namespace chimera::kinematics
