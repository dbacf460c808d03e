#pragma once
// The shipped arm's kinematic chain for tests that check modules against it.

#include <memory>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "kinematics/arm_chain.hpp"
#include "kinematics/pose.hpp"

namespace chimera::test {

inline kinematics::ArmChain& shipped_chain() {
  static std::unique_ptr<kinematics::ArmChain> chain = [] {
    auto c = kinematics::ArmChain::load("");
    EXPECT_TRUE(c.ok()) << (c.ok() ? "" : c.error().message);
    return c.ok() ? std::move(c).value() : nullptr;
  }();
  return *chain;
}

/// The shipped arm's tool pose at q, as 6 numbers.
inline std::vector<double> tool_pose(std::span<const double> q) {
  std::vector<double> x(6);
  kinematics::write_pose(shipped_chain().forward(q), x);
  return x;
}

/// Position and orientation error between two 6-number poses.
inline kinematics::Vector6 pose_difference(std::span<const double> a, std::span<const double> b) {
  return kinematics::pose_error(kinematics::pose_from(a), kinematics::pose_from(b));
}

}  // namespace chimera::test
