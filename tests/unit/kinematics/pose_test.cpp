// The pose algebra of the kinematics modules: rotation vectors and the pose error, including
// the places where they are delicate (angles near 0 and near pi).

#include "kinematics/pose.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

namespace chimera::kinematics {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(Pose, RotationVectorsRoundTripAtEveryAngle) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  for (const double angle : {0.0, 1e-9, 1e-4, 0.3, 1.0, 2.0, 3.0, kPi - 1e-6}) {
    const Eigen::Vector3d r = angle * axis;
    const Eigen::Matrix3d rotation = rotation_from_vector(r);
    EXPECT_TRUE((rotation * rotation.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-14));
    EXPECT_NEAR(rotation.determinant(), 1.0, 1e-14);
    EXPECT_LT((rotation_vector(rotation) - r).norm(), 1e-12) << "angle " << angle;
  }
}

TEST(Pose, TheRotationVectorOfAHalfTurnHasAngleExactlyPi) {
  // Turned upside down about x: the tool pointing down, as an arm's tool often is. Either sign of
  // the axis names the same rotation; its matrix is what the modules use.
  const Eigen::Matrix3d down = Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d r = rotation_vector(down);
  EXPECT_NEAR(r.norm(), kPi, 1e-12);
  EXPECT_NEAR(std::fabs(r.x()), kPi, 1e-12);
  EXPECT_TRUE(rotation_from_vector(r).isApprox(down, 1e-12));
  EXPECT_TRUE(rotation_from_vector(-r).isApprox(down, 1e-12));
}

TEST(Pose, AngleAboveAPiWrapsToTheSameRotation) {
  const Eigen::Vector3d r(0.0, 0.0, kPi + 0.2);
  const Eigen::Vector3d principal = rotation_vector(rotation_from_vector(r));
  EXPECT_NEAR(principal.z(), -(kPi - 0.2), 1e-12);
  EXPECT_LE(principal.norm(), kPi);
}

TEST(Pose, SixNumbersRoundTrip) {
  const std::array<double, 6> x{0.4, -0.1, 0.9, 0.2, 2.2, -0.3};
  std::array<double, 6> back{};
  write_pose(pose_from(x), back);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(back[i], x[i], 1e-12) << i;
}

TEST(Pose, ErrorIsZeroBetweenEqualPosesAndAntisymmetric) {
  const Pose a = pose_from(std::array<double, 6>{0.4, -0.1, 0.9, 0.2, 2.2, -0.3});
  const Pose b = pose_from(std::array<double, 6>{0.5, 0.1, 0.8, -0.4, 2.0, 0.1});
  EXPECT_LT(pose_error(a, a).norm(), 1e-12);
  // The orientation part is expressed in the base frame, so swapping the poses negates it.
  EXPECT_LT((pose_error(a, b) + pose_error(b, a)).norm(), 1e-12);
}

TEST(Pose, DisplaceUndoesTheError) {
  const Pose a = pose_from(std::array<double, 6>{0.4, -0.1, 0.9, 0.2, 2.2, -0.3});
  const Pose b = pose_from(std::array<double, 6>{0.5, 0.1, 0.8, -0.4, 2.0, 0.1});
  const Pose there = displace(b, pose_error(a, b));
  EXPECT_LT(pose_error(a, there).norm(), 1e-12);
}

TEST(Pose, StepTowardGoesTheFractionOfTheWay) {
  const Pose a = pose_from(std::array<double, 6>{0.0, 0.0, 1.0, 0.0, 0.0, 0.0});
  const Pose b = pose_from(std::array<double, 6>{0.2, -0.4, 1.0, 0.0, 0.0, 1.2});
  const Pose half = step_toward(a, b, 0.5);
  EXPECT_NEAR(half.position.x(), 0.1, 1e-15);
  EXPECT_NEAR(half.position.y(), -0.2, 1e-15);
  EXPECT_NEAR(rotation_vector(half.rotation).z(), 0.6, 1e-12);
  EXPECT_LT(pose_error(step_toward(a, b, 0.0), a).norm(), 1e-12);
  EXPECT_LT(pose_error(step_toward(a, b, 1.0), b).norm(), 1e-12);
}

TEST(Pose, ErrorAcrossTheHalfTurnIsSmall) {
  // Two orientations a little either side of a half turn have rotation vectors far apart
  // (r and nearly -r), yet the error between them is the small angle that separates them.
  const Pose a = pose_from(std::array<double, 6>{0, 0, 0, kPi - 0.01, 0, 0});
  const Pose b = pose_from(std::array<double, 6>{0, 0, 0, -(kPi - 0.01), 0, 0});
  EXPECT_NEAR(orientation_norm(pose_error(a, b)), 0.02, 1e-12);
}

}  // namespace
}  // namespace chimera::kinematics
