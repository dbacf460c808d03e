#pragma once
// Numeric inverse kinematics within joint limits, for the inv_kin module: the joint positions
// whose tip pose is a given pose, found by Levenberg-Marquardt iteration from a seed, every iterate
// clamped into the joint limits.

#include <span>
#include <vector>

#include "kinematics/arm_chain.hpp"
#include "kinematics/pose.hpp"

namespace chimera::kinematics {

struct IkSettings {
  int max_iterations = 50;              // per solve(): bounds its time
  double position_tolerance = 1e-9;     // m: converged when both errors are below their tolerance
  double orientation_tolerance = 1e-9;  // rad
  double damping = 1e-6;                // m^2: Sugihara's bias term, the damping that remains at E = 0
  double max_step = 0.5;                // rad (or m): the largest change of one joint per iteration
};

struct IkOutcome {
  bool converged = false;
  int iterations = 0;
  double position_error = 0.0;     // m, |p_target - p(q)|
  double orientation_error = 0.0;  // rad, angle of R_target R(q)^T
};

/// Levenberg-Marquardt with the damping of Sugihara (2011): with e the pose error (pose_error) and
/// E = e.e / 2, each iteration solves
///     dq = J^T (J J^T + (E + damping) I)^-1 e,
/// which is Gauss-Newton near a solution (E -> 0) and a short gradient step far from one or near
/// a singularity. The step is scaled so no joint moves more than max_step, and q + dq is clamped
/// into [lower, upper]; a joint held at a limit by the clamp is left out of the next solve (its
/// column of J is zeroed) while the error pulls it further out. A step that does not reduce E is
/// halved, up to 8 times; if none does, q is a local minimum within the limits and the solver
/// stops there. The result is always within the limits, and the best q seen.
class IkSolver {
 public:
  /// Limits of ndof entries each (lower <= upper). Allocates; not real-time safe.
  IkSolver(ArmChain& chain, std::vector<double> lower, std::vector<double> upper, IkSettings settings = {});

  /// The joint positions whose tip pose is `target`, starting from `seed`, written to q (both
  /// ndof entries). Real-time safe: no allocation, at most max_iterations * 9 evaluations.
  IkOutcome solve(const Pose& target, std::span<const double> seed, std::span<double> q) noexcept;

  [[nodiscard]] std::span<const double> lower() const noexcept { return lower_; }
  [[nodiscard]] std::span<const double> upper() const noexcept { return upper_; }
  [[nodiscard]] const IkSettings& settings() const noexcept { return settings_; }

 private:
  ArmChain& chain_;
  std::vector<double> lower_;
  std::vector<double> upper_;
  IkSettings settings_;
};

}  // namespace chimera::kinematics
