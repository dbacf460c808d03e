#pragma once
// The moving target that the simulated vision subsystem (visual_servo) watches: a pose that moves
// about a centre, each of its 6 numbers on a sine wave of its own (a Lissajous figure in space).

#include <array>
#include <cmath>
#include <numbers>
#include <span>

#include "kinematics/pose.hpp"

namespace chimera::modules {

struct TargetPathSettings {
  std::array<double, 6> center{};     // pose [x y z rx ry rz]: m, rotation vector in rad
  std::array<double, 6> amplitude{};  // m for x y z, rad for rx ry rz
  std::array<double, 6> frequency{};  // Hz
  std::array<double, 6> phase{};      // rad
};

/// x_i(t) = center_i + amplitude_i sin(2 pi frequency_i t + phase_i), i = 0..5; the last three
/// are the components of a rotation vector (near the centre's orientation, a sine on one of them
/// is a rocking of the target about that base axis).
class TargetPath {
 public:
  TargetPath() = default;
  explicit TargetPath(const TargetPathSettings& s) : s_(s) {}

  /// The 6 numbers at time t (s). Real-time safe.
  void sample(double t, std::span<double> x) const noexcept {
    for (std::size_t i = 0; i < 6; ++i)
      x[i] = s_.center[i] + s_.amplitude[i] * std::sin(2.0 * std::numbers::pi * s_.frequency[i] * t + s_.phase[i]);
  }
  /// The pose at time t (s). Real-time safe.
  [[nodiscard]] kinematics::Pose at(double t) const noexcept {
    std::array<double, 6> x{};
    sample(t, x);
    return kinematics::pose_from(x);
  }
  [[nodiscard]] const TargetPathSettings& settings() const noexcept { return s_; }

 private:
  TargetPathSettings s_;
};

}  // namespace chimera::modules
