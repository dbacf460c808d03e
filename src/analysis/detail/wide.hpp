#pragma once
// 128-bit integers for sums of C over long intervals, which can pass 2^63 before a test ends.
// Private to src/analysis.

namespace chimera::analysis::detail {

// __extension__: GCC and Clang have __int128, but -Wpedantic warns of it in ISO C++ mode.
__extension__ typedef __int128 Wide;  // NOLINT(modernize-use-using): `using` cannot carry __extension__

/// Greatest common divisor of two positive numbers (std::gcd takes no __int128).
inline Wide gcd(Wide a, Wide b) {
  while (b != 0) {
    const Wide r = a % b;
    a = b;
    b = r;
  }
  return a;
}

}  // namespace chimera::analysis::detail
