#include "kinematics/ik_solver.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Cholesky>

namespace chimera::kinematics {
namespace {

constexpr int kHalvings = 8;
constexpr double kMinBias = 1e-12;  // m^2: far below any squared singular value that matters
constexpr double kMaxBias = 1.0;    // m^2: a step of a few mm at most; beyond it the solver gives up

double half_squared(const Vector6& e) noexcept { return 0.5 * e.squaredNorm(); }

}  // namespace

IkSolver::IkSolver(ArmChain& chain, std::vector<double> lower, std::vector<double> upper, IkSettings settings)
    : chain_(chain), lower_(std::move(lower)), upper_(std::move(upper)), settings_(settings) {}

IkOutcome IkSolver::solve(const Pose& target, std::span<const double> seed, std::span<double> q) noexcept {
  const int n = chain_.ndof();
  const auto at = [](int i) { return static_cast<std::size_t>(i); };
  JointVector current(n);
  for (int i = 0; i < n; ++i) current[i] = std::clamp(seed[at(i)], lower_[at(i)], upper_[at(i)]);

  Pose pose;
  JacobianMatrix jacobian(6, n);
  chain_.evaluate({current.data(), at(n)}, pose, jacobian);
  Vector6 error = pose_error(target, pose);
  double energy = half_squared(error);

  IkOutcome out;
  const auto converged = [&](const Vector6& e) {
    return position_norm(e) < settings_.position_tolerance && orientation_norm(e) < settings_.orientation_tolerance;
  };
  JointVector trial(n);
  double bias = settings_.damping;  // shrinks while steps succeed, grows when they fail
  while (!converged(error) && out.iterations < settings_.max_iterations) {
    ++out.iterations;
    // Joints pinned at a limit that the error pushes further out take no part in this step.
    const JointVector gradient = jacobian.transpose() * error;
    for (int i = 0; i < n; ++i) {
      const bool pinned_low = current[i] <= lower_[at(i)] && gradient[i] < 0.0;
      const bool pinned_high = current[i] >= upper_[at(i)] && gradient[i] > 0.0;
      if (pinned_low || pinned_high) jacobian.col(i).setZero();
    }
    const Eigen::Matrix<double, 6, 6> a =
        jacobian * jacobian.transpose() + (energy + bias) * Eigen::Matrix<double, 6, 6>::Identity();
    const Vector6 weights = a.ldlt().solve(error);
    JointVector step = JointVector::Zero(n);
    step.noalias() = jacobian.transpose() * weights;
    const double largest = step.cwiseAbs().maxCoeff();
    if (largest > settings_.max_step) step *= settings_.max_step / largest;

    bool improved = false;
    Vector6 trial_error;
    for (int h = 0; h <= kHalvings && !improved; ++h, step *= 0.5) {
      for (int i = 0; i < n; ++i) trial[i] = std::clamp(current[i] + step[i], lower_[at(i)], upper_[at(i)]);
      chain_.evaluate({trial.data(), at(n)}, pose, jacobian);
      trial_error = pose_error(target, pose);
      improved = half_squared(trial_error) < energy;
    }
    if (!improved) {
      if (bias >= kMaxBias) break;  // a local minimum within the limits: nothing left to gain
      bias = std::min(bias * 100.0, kMaxBias);
      continue;
    }
    bias = std::max(bias * 0.1, kMinBias);
    current = trial;
    error = trial_error;
    energy = half_squared(error);
  }
  // The Jacobian left over belongs to the last trial, which is `current` whenever it improved.
  for (int i = 0; i < n; ++i) q[at(i)] = current[i];
  out.converged = converged(error);
  out.position_error = position_norm(error);
  out.orientation_error = orientation_norm(error);
  return out;
}

}  // namespace chimera::kinematics
