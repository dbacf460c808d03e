#pragma once
// Deterministic Gaussian noise for simulated sensors (the arm's encoders, the vision subsystem):
// Box-Muller on splitmix64. A few lines, fully specified, so a seed gives the same sequence on
// every platform and standard library (std::normal_distribution is implementation-defined).

#include <cmath>
#include <cstdint>
#include <numbers>

namespace chimera::sim {

class GaussianNoise {
 public:
  explicit GaussianNoise(std::uint64_t seed = 1) noexcept : state_(seed) {}

  /// Restarts the sequence from `seed`. Real-time safe.
  void reseed(std::uint64_t seed) noexcept {
    state_ = seed;
    has_spare_ = false;
  }

  /// The next sample of the standard normal distribution. Real-time safe.
  double next() noexcept {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    constexpr double kScale = 1.0 / 9007199254740992.0;                           // 2^-53
    const double u1 = (static_cast<double>(splitmix64() >> 11U) + 1.0) * kScale;  // (0, 1]
    const double u2 = static_cast<double>(splitmix64() >> 11U) * kScale;
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double phi = 2.0 * std::numbers::pi * u2;
    spare_ = r * std::sin(phi);  // Box-Muller yields normals in pairs
    has_spare_ = true;
    return r * std::cos(phi);
  }

 private:
  std::uint64_t splitmix64() noexcept {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31U);
  }

  std::uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace chimera::sim
