#include "chimera/analysis/utilisation.hpp"

#include <cmath>

#include "detail/wide.hpp"

namespace chimera::analysis {

double utilisation(std::span<const Demand> tasks) {
  long double u = 0;
  for (const auto& t : tasks) u += static_cast<long double>(t.c_ns) / static_cast<long double>(t.t_ns);
  return static_cast<double>(u);
}

bool utilisation_at_most_one(std::span<const Demand> tasks) {
  // sum C_i/T_i as one fraction num/den, den = lcm(T_i); exact while den fits.
  using detail::Wide;
  constexpr Wide kLimit = (static_cast<Wide>(1) << 120);
  Wide num = 0;
  Wide den = 1;
  for (const auto& t : tasks) {
    if (t.c_ns > t.t_ns) return false;  // one task alone needs more than the processor
    const Wide period = t.t_ns;
    const Wide g = detail::gcd(den, period);
    const Wide scale = period / g;  // den * scale = lcm(den, period)
    if (den > kLimit / scale) {
      long double u = 0;
      for (const auto& x : tasks) u += static_cast<long double>(x.c_ns) / static_cast<long double>(x.t_ns);
      return u <= 1.0L;
    }
    // Both terms stay below lcm <= 2^120: num <= den (checked below) and C <= T.
    num = num * scale + static_cast<Wide>(t.c_ns) * (den / g);
    den *= scale;
    if (num > den) return false;  // the sum only grows
  }
  return num <= den;
}

double liu_layland_bound(int n) {
  if (n <= 0) return 1.0;
  return n * (std::pow(2.0, 1.0 / n) - 1.0);
}

}  // namespace chimera::analysis
