// The allocator hook of `chimera run --rt-check`: the C allocator of this program, replaced by
// thin wrappers that tell libchimera about each allocation and forward to glibc's own. Every
// allocation of the process passes here (libstdc++'s operator new and new[] call malloc, and so
// does a C module), so replacing the C functions catches both without counting twice. Outside a
// task's real-time method under --rt-check, the only cost is a call that reads one thread-local
// pointer. free is replaced too, so that every block goes back to the allocator it came from.

#include <cerrno>
#include <cstddef>

#include "chimera/exec/rt_check.hpp"

extern "C" {
void* __libc_malloc(std::size_t);                 // NOLINT(bugprone-reserved-identifier): glibc's allocator
void* __libc_calloc(std::size_t, std::size_t);    // NOLINT(bugprone-reserved-identifier): same
void* __libc_realloc(void*, std::size_t);         // NOLINT(bugprone-reserved-identifier): same
void* __libc_memalign(std::size_t, std::size_t);  // NOLINT(bugprone-reserved-identifier): same
void __libc_free(void*);                          // NOLINT(bugprone-reserved-identifier): same

void* malloc(std::size_t n) {  // NOLINT(readability-inconsistent-declaration-parameter-name): replaces glibc's
  chimera::rt_check::note_allocation();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {  // NOLINT: replaces glibc's
  chimera::rt_check::note_allocation();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {  // NOLINT: replaces glibc's
  chimera::rt_check::note_allocation();
  return __libc_realloc(p, n);
}
void* memalign(std::size_t alignment, std::size_t n) {  // NOLINT: replaces glibc's
  chimera::rt_check::note_allocation();
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {  // NOLINT: replaces glibc's (aligned operator new)
  chimera::rt_check::note_allocation();
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {  // NOLINT: replaces glibc's
  chimera::rt_check::note_allocation();
  *out = __libc_memalign(alignment, n);
  return *out != nullptr ? 0 : ENOMEM;
}
void free(void* p) { __libc_free(p); }  // NOLINT: replaces glibc's, pairing with the above
}
