#include "futex.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <climits>

#include "chimera/exec/clock.hpp"

namespace chimera::detail {

namespace {
long futex(const std::atomic<std::uint32_t>& word, int op, std::uint32_t value, const timespec* timeout) noexcept {
  // The kernel reads the word itself; the cast drops const because the syscall's type demands it.
  auto* addr = const_cast<std::uint32_t*>(reinterpret_cast<const std::uint32_t*>(&word));  // NOLINT: syscall ABI
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-vararg): glibc has no futex wrapper; syscall() is the way in
  return syscall(SYS_futex, addr, op, value, timeout, nullptr, FUTEX_BITSET_MATCH_ANY);
}
}  // namespace

bool futex_wait(const std::atomic<std::uint32_t>& word, std::uint32_t expected, std::int64_t deadline_ns,
                FutexScope scope) noexcept {
  // FUTEX_WAIT_BITSET takes an absolute CLOCK_MONOTONIC time, so no drift from relative waits.
  const timespec ts = to_timespec(deadline_ns < 0 ? 0 : deadline_ns);
  const int op = FUTEX_WAIT_BITSET | (scope == FutexScope::kProcess ? FUTEX_PRIVATE_FLAG : 0);
  const long r = futex(word, op, expected, deadline_ns < 0 ? nullptr : &ts);
  return !(r == -1 && errno == ETIMEDOUT);
}

void futex_wake_all(const std::atomic<std::uint32_t>& word, FutexScope scope) noexcept {
  (void)futex(word, FUTEX_WAKE_BITSET | (scope == FutexScope::kProcess ? FUTEX_PRIVATE_FLAG : 0), INT_MAX, nullptr);
}

}  // namespace chimera::detail
