#pragma once
// The pid_joint module's control law, apart from the framework so that tests and tools can use
// it directly.

#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

namespace chimera::modules {

/// Per-joint gains and limits, each ndof long.
struct PidGains {
  std::vector<double> kp;       // N*m/rad
  std::vector<double> ki;       // N*m/(rad*s)
  std::vector<double> kd;       // N*m*s/rad
  std::vector<double> tau_max;  // N*m, output saturation
  std::vector<double> i_max;    // rad*s, bound on the integral of the error
};

/// Independent joint PID (Craig 1989, 10.7):
///   e = theta_d - theta_m,  tau = kp e + ki int(e) dt + kd (dtheta_d - dtheta_m),
/// saturated to +-tau_max. Anti-windup: the integral is bounded by +-i_max, and a joint whose
/// output is saturated in the direction of its error stops integrating (conditional integration).
class PidLaw {
 public:
  /// Allocates; not real-time safe. dt_s is the sampling period.
  void configure(PidGains gains, double dt_s) {
    g_ = std::move(gains);
    dt_ = dt_s;
    integral_.assign(g_.kp.size(), 0.0);
  }

  /// Forgets the integral. Real-time safe.
  void reset() noexcept { std::fill(integral_.begin(), integral_.end(), 0.0); }

  /// One sample; all spans ndof long. Real-time safe.
  void update(std::span<const double> theta_d, std::span<const double> dtheta_d, std::span<const double> theta_m,
              std::span<const double> dtheta_m, std::span<double> tau) noexcept {
    for (std::size_t i = 0; i < integral_.size(); ++i) {
      const double e = theta_d[i] - theta_m[i];
      const double pd = g_.kp[i] * e + g_.kd[i] * (dtheta_d[i] - dtheta_m[i]);
      const double grown = std::clamp(integral_[i] + e * dt_, -g_.i_max[i], g_.i_max[i]);
      double u = pd + g_.ki[i] * grown;
      // Integrating further would only push a saturated output deeper into saturation.
      const bool winding_up = (u > g_.tau_max[i] && e > 0.0) || (u < -g_.tau_max[i] && e < 0.0);
      if (winding_up) {
        u = pd + g_.ki[i] * integral_[i];
      } else {
        integral_[i] = grown;
      }
      tau[i] = std::clamp(u, -g_.tau_max[i], g_.tau_max[i]);
    }
  }

  [[nodiscard]] std::span<const double> integral() const noexcept { return integral_; }

 private:
  PidGains g_;
  double dt_ = 0.0;
  std::vector<double> integral_;
};

}  // namespace chimera::modules
