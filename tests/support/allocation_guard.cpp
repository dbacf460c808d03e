// The replacement allocator behind AllocationGuard: forwards to glibc's own allocator and counts
// while armed.

#include "support/allocation_guard.hpp"

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <new>

extern "C" {
void* __libc_malloc(std::size_t);                 // NOLINT: glibc's allocator, which the hooks forward to
void* __libc_calloc(std::size_t, std::size_t);    // NOLINT: same
void* __libc_realloc(void*, std::size_t);         // NOLINT: same
void* __libc_memalign(std::size_t, std::size_t);  // NOLINT: same
void __libc_free(void*);                          // NOLINT: same
}

namespace {
// relaxed throughout: a switch and a counter, read after the counted threads are parked or joined
std::atomic<bool> g_armed{false};     // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): the switch
std::atomic<bool> g_fail_new{false};  // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): the mode
std::atomic<long> g_allocations{0};   // NOLINT(cppcoreguidelines-avoid-non-const-global-variables): the count

bool note() {
  if (!g_armed.load(std::memory_order_relaxed)) return false;
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return true;
}
}  // namespace

namespace chimera::testing {
AllocationGuard::AllocationGuard(OnNew on_new) {
  g_allocations.store(0, std::memory_order_relaxed);
  g_fail_new.store(on_new == OnNew::kFail, std::memory_order_relaxed);
  g_armed.store(true, std::memory_order_seq_cst);  // seq_cst: armed before the code under test runs
}
AllocationGuard::~AllocationGuard() { g_armed.store(false, std::memory_order_seq_cst); }
long AllocationGuard::count() { return g_allocations.load(std::memory_order_relaxed); }
}  // namespace chimera::testing

extern "C" {
void* malloc(std::size_t n) {  // NOLINT: replaces the C allocator of this test program
  note();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t m) {  // NOLINT: same
  note();
  return __libc_calloc(n, m);
}
void* realloc(void* p, std::size_t n) {  // NOLINT: same
  note();
  return __libc_realloc(p, n);
}
void* memalign(std::size_t a, std::size_t n) {  // NOLINT: same
  note();
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) {  // NOLINT: same
  note();
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, std::size_t a, std::size_t n) {  // NOLINT: same
  note();
  *out = __libc_memalign(a, n);
  return *out != nullptr ? 0 : ENOMEM;
}
void free(void* p) { __libc_free(p); }  // NOLINT: same
}

// noinline: GCC 12 otherwise pairs an inlined free() with operator new and warns
// (-Wmismatched-new-delete), although the replacements are a matched pair.
[[gnu::noinline]] void* operator new(std::size_t n) {
  if (note() && g_fail_new.load(std::memory_order_relaxed)) throw std::bad_alloc();
  if (void* p = __libc_malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new[](std::size_t n) { return operator new(n); }
[[gnu::noinline]] void operator delete(void* p) noexcept { __libc_free(p); }
[[gnu::noinline]] void operator delete[](void* p) noexcept { __libc_free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t /*size*/) noexcept { __libc_free(p); }
[[gnu::noinline]] void operator delete[](void* p, std::size_t /*size*/) noexcept { __libc_free(p); }
