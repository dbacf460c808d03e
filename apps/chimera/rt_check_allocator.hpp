#pragma once
// Whether this chimera program counts allocations for --rt-check (rt_check_allocator.cpp).

namespace chimera::cli {

#if defined(CHIMERA_RT_CHECK_ALLOCATOR)
inline constexpr bool kRtCheckAllocator = true;
#else
inline constexpr bool kRtCheckAllocator = false;  // a sanitized build: its allocator is the sanitizer's
#endif

}  // namespace chimera::cli
