#pragma once
// Proves that code allocates nothing: while an AllocationGuard lives, every allocation in the
// process (malloc, calloc, realloc, aligned allocations, operator new) is counted, and operator
// new may be made to fail by throwing std::bad_alloc. The replacement allocator lives in
// allocation_guard.cpp, which is linked only into plain (unsanitized) test programs: a sanitizer
// brings its own allocator, and those programs define CHIMERA_ALLOCATION_GUARD=1.

namespace chimera::testing {

class AllocationGuard {
 public:
  enum class OnNew { kCount, kFail };
  explicit AllocationGuard(OnNew on_new = OnNew::kCount);
  ~AllocationGuard();
  AllocationGuard(const AllocationGuard&) = delete;
  AllocationGuard& operator=(const AllocationGuard&) = delete;

  /// Allocations since this guard was armed.
  [[nodiscard]] static long count();
};

}  // namespace chimera::testing
