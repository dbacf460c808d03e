#pragma once
// Time sources. The subsystem's clock is either the wall clock (CLOCK_MONOTONIC) or a simulated
// one; execution times are always measured on the monotonic clock, since they are real work.

#include <cstdint>
#include <ctime>

namespace chimera {

/// The subsystem's clock: the wall clock with real-time threads, or simulated time (deterministic,
/// as fast as the machine allows).
enum class ClockKind { kReal, kVirtual };

/// CLOCK_MONOTONIC in nanoseconds. Real-time safe (vDSO, no system call on Linux x86-64).
inline std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

inline timespec to_timespec(std::int64_t ns) noexcept {
  return timespec{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

}  // namespace chimera
