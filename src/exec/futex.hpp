#pragma once
// Sleeping on a 32-bit atomic word (Linux futex). Synchronisation itself is done with the
// atomics' memory orders; the futex only puts a thread to sleep and wakes it.

#include <atomic>
#include <cstdint>

namespace chimera::detail {

static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t), "futex needs a plain 32-bit word");

/// Whether sleepers and wakers may be in different processes, the word in shared memory. A word
/// private to one process takes the kernel's cheaper path; both sides must say the same.
enum class FutexScope : std::uint8_t { kProcess, kShared };

/// Sleeps while `word` holds `expected`, until woken or until the absolute CLOCK_MONOTONIC time
/// `deadline_ns` (< 0: no deadline). Returns false on timeout. Spurious returns are possible.
bool futex_wait(const std::atomic<std::uint32_t>& word, std::uint32_t expected, std::int64_t deadline_ns,
                FutexScope scope = FutexScope::kProcess) noexcept;
/// Wakes every thread sleeping on `word`.
void futex_wake_all(const std::atomic<std::uint32_t>& word, FutexScope scope = FutexScope::kProcess) noexcept;

/// One step of a spin-wait: tells the CPU (and a hypervisor) that this thread is only waiting.
inline void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

}  // namespace chimera::detail
