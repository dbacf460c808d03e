// Inverse kinematics round trips on the shipped arm: from a pose that forward kinematics gives,
// the solver finds joint positions with that pose, always within the joint limits, and the best
// pose the limits allow when the exact one lies outside them.

#include "kinematics/ik_solver.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "kinematics/arm_chain.hpp"
#include "support/allocation_guard.hpp"

namespace chimera::kinematics {
namespace {

std::unique_ptr<ArmChain> load_chain() {
  auto chain = ArmChain::load("");
  EXPECT_TRUE(chain.ok()) << (chain.ok() ? "" : chain.error().message);
  return chain.ok() ? std::move(chain).value() : nullptr;
}

std::vector<double> limits_of(std::span<const double> s) { return {s.begin(), s.end()}; }

IkSolver make_solver(ArmChain& chain, IkSettings settings = {}) {
  return IkSolver(chain, limits_of(chain.lower()), limits_of(chain.upper()), settings);
}

// A fixed pseudo-random sequence in [0, 1).
class Uniform {
 public:
  double operator()() {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state_ >> 11U) / 9007199254740992.0;
  }

 private:
  std::uint64_t state_ = 2024;
};

bool within(std::span<const double> q, std::span<const double> lower, std::span<const double> upper) {
  for (std::size_t i = 0; i < q.size(); ++i)
    if (q[i] < lower[i] || q[i] > upper[i]) return false;
  return true;
}

// The arm's singular postures: the elbow stretched or folded (+-pi/2), the wrist straight (0).
bool near_singular(const std::vector<double>& q, double margin) {
  return std::fabs(std::fabs(q[2]) - std::numbers::pi / 2) < margin || std::fabs(q[4]) < margin;
}

// A posture 0.3 rad inside the limits and away from singular postures (RoundTripsNearSingular-
// Postures has those), and a seed up to `spread` / 2 away from it on every joint.
struct Sample {
  std::vector<double> truth;
  std::vector<double> seed;
};
Sample draw(Uniform& uniform, const ArmChain& chain, double spread) {
  Sample s{std::vector<double>(6), std::vector<double>(6)};
  do {
    for (std::size_t i = 0; i < 6; ++i) {
      const double lo = chain.lower()[i] + 0.3;
      const double hi = chain.upper()[i] - 0.3;
      s.truth[i] = lo + uniform() * (hi - lo);
      s.seed[i] = s.truth[i] + spread * (uniform() - 0.5);
    }
  } while (near_singular(s.truth, 0.05));
  return s;
}

TEST(IkSolver, RoundTripsFromANearbySeed) {
  auto chain = load_chain();
  ASSERT_NE(chain, nullptr);
  IkSettings settings;
  settings.max_iterations = 100;
  IkSolver ik = make_solver(*chain, settings);
  Uniform uniform;
  double worst_position = 0.0;
  double worst_orientation = 0.0;
  int worst_iterations = 0;
  for (int k = 0; k < 300; ++k) {
    const auto [truth, seed] = draw(uniform, *chain, 1.0);
    const Pose target = chain->forward(truth);
    std::vector<double> q(6);
    const IkOutcome out = ik.solve(target, seed, q);
    ASSERT_TRUE(out.converged) << "sample " << k << ": " << out.position_error << " m, " << out.orientation_error
                               << " rad after " << out.iterations << " iterations";
    const Vector6 e = pose_error(target, chain->forward(q));
    worst_position = std::max(worst_position, position_norm(e));
    worst_orientation = std::max(worst_orientation, orientation_norm(e));
    worst_iterations = std::max(worst_iterations, out.iterations);
    EXPECT_TRUE(within(q, chain->lower(), chain->upper()));
  }
  std::cout << "IK round trips (300, seeds within 0.5 rad): worst position error " << worst_position
            << " m, orientation " << worst_orientation << " rad, at most " << worst_iterations << " iterations\n";
  EXPECT_LT(worst_position, 1e-9);
  EXPECT_LT(worst_orientation, 1e-9);
}

TEST(IkSolver, RoundTripsNearSingularPostures) {
  auto chain = load_chain();
  ASSERT_NE(chain, nullptr);
  IkSettings settings;
  settings.max_iterations = 200;
  IkSolver ik = make_solver(*chain, settings);
  // 0.01 to 0.05 rad from the stretched and the folded elbow, with the wrist bent or nearly straight.
  for (const double elbow : {1.52, 1.55, 1.56, -1.52, -1.55, -1.56}) {
    for (const double pitch : {0.8, 0.02}) {
      const std::vector<double> truth{0.3, 0.2, elbow, 0.4, pitch, -0.3};
      const std::vector<double> seed{0.4, 0.1, elbow - 0.1, 0.5, pitch + 0.1, -0.2};
      const Pose target = chain->forward(truth);
      std::vector<double> q(6);
      const IkOutcome out = ik.solve(target, seed, q);
      EXPECT_TRUE(out.converged) << "elbow " << elbow << ", pitch " << pitch << ": " << out.position_error << " m";
      EXPECT_LT(position_norm(pose_error(target, chain->forward(q))), 1e-9);
    }
  }
}

TEST(IkSolver, ReachesPosesFromDistantSeedsWithinTheLimits) {
  auto chain = load_chain();
  ASSERT_NE(chain, nullptr);
  IkSettings settings;
  settings.max_iterations = 200;
  IkSolver ik = make_solver(*chain, settings);
  Uniform uniform;
  int converged = 0;
  constexpr int kTried = 200;
  for (int k = 0; k < kTried; ++k) {
    const auto [truth, seed] = draw(uniform, *chain, 2.0);  // up to 1 rad away on every joint
    const Pose target = chain->forward(truth);
    std::vector<double> q(6);
    const IkOutcome out = ik.solve(target, seed, q);
    EXPECT_TRUE(within(q, chain->lower(), chain->upper()));
    if (out.converged) {
      ++converged;
      EXPECT_LT(position_norm(pose_error(target, chain->forward(q))), 1e-9);
    }
  }
  // A local solver may end in a minimum at a limit, on the far side of which the pose lies; from
  // seeds this far it must still reach nearly every pose (measured: 98%).
  std::cout << "IK from seeds up to 1 rad away: " << converged << " of " << kTried << " poses solved\n";
  EXPECT_GE(converged, 190);
}

TEST(IkSolver, ASolutionOutsideTheLimitsGivesTheBestPoseWithinThem) {
  auto chain = load_chain();
  ASSERT_NE(chain, nullptr);
  // The exact solution bends the elbow to 1.0 rad; this arm's elbow may bend only to 0.6.
  std::vector<double> lower = limits_of(chain->lower());
  std::vector<double> upper = limits_of(chain->upper());
  upper[2] = 0.6;
  IkSolver ik(*chain, lower, upper);
  const std::vector<double> truth{0.2, 0.3, 1.0, 0.4, 0.8, -0.2};
  const Pose target = chain->forward(truth);
  std::vector<double> q(6);
  const IkOutcome out = ik.solve(target, std::vector<double>{0.2, 0.3, 0.5, 0.4, 0.8, -0.2}, q);
  EXPECT_FALSE(out.converged);
  EXPECT_TRUE(within(q, lower, upper));
  EXPECT_DOUBLE_EQ(q[2], 0.6);  // pressed against the limit
  EXPECT_GT(out.position_error, 1e-3);
  // The other joints made up for it: closer than the seed's pose, and than truth with the elbow clamped.
  auto clamped = truth;
  clamped[2] = 0.6;
  EXPECT_LT(out.position_error, position_norm(pose_error(target, chain->forward(clamped))));
  EXPECT_NEAR(out.position_error, position_norm(pose_error(target, chain->forward(q))), 1e-12);
}

TEST(IkSolver, ASeedOutsideTheLimitsIsClampedFirst) {
  auto chain = load_chain();
  ASSERT_NE(chain, nullptr);
  IkSolver ik = make_solver(*chain);
  const std::vector<double> truth{0.2, 0.3, 1.0, 0.4, 0.8, -0.2};
  std::vector<double> seed = truth;
  seed[4] = 5.0;  // beyond the wrist pitch's 1.75
  std::vector<double> q(6);
  const IkOutcome out = ik.solve(chain->forward(truth), seed, q);
  EXPECT_TRUE(out.converged);
  EXPECT_TRUE(within(q, chain->lower(), chain->upper()));
}

TEST(IkSolver, AnUnreachablePoseStretchesTheArmTowardIt) {
  auto chain = load_chain();
  ASSERT_NE(chain, nullptr);
  IkSettings settings;
  settings.max_iterations = 200;
  IkSolver ik = make_solver(*chain, settings);
  Pose target = chain->forward(std::vector<double>(6, 0.0));
  target.position = Eigen::Vector3d(2.5, 0.1, 0.7);  // 2.5 m out: the arm reaches about 1 m
  const std::vector<double> seed{0.0, 0.2, 0.6, 0.0, 0.5, 0.0};
  std::vector<double> q(6);
  const IkOutcome out = ik.solve(target, seed, q);
  EXPECT_FALSE(out.converged);
  EXPECT_TRUE(within(q, chain->lower(), chain->upper()));
  EXPECT_TRUE(std::isfinite(out.position_error));
  // Closer than where it started, and the tool is out toward +x, beyond 0.8 m from the waist axis.
  EXPECT_LT(out.position_error, position_norm(pose_error(target, chain->forward(seed))));
  EXPECT_GT(chain->forward(q).position.x(), 0.8);
}

#if CHIMERA_ALLOCATION_GUARD  // plain builds: a sanitizer brings its own allocator
TEST(IkSolver, SolvingDoesNotAllocate) {
  auto chain = load_chain();
  ASSERT_NE(chain, nullptr);
  IkSolver ik = make_solver(*chain);
  const Pose target = chain->forward(std::vector<double>{0.2, 0.3, 1.0, 0.4, 0.8, -0.2});
  const std::vector<double> seed{0.0, 0.0, 0.5, 0.0, 0.5, 0.0};
  std::vector<double> q(6);
  long allocations = 0;
  IkOutcome out;
  {
    testing::AllocationGuard guard;
    out = ik.solve(target, seed, q);
    allocations = testing::AllocationGuard::count();
  }
  EXPECT_TRUE(out.converged);
  EXPECT_EQ(allocations, 0);
}
#endif

}  // namespace
}  // namespace chimera::kinematics
