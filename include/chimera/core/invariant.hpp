#pragma once
// Invariants of our own code (STYLE's third kind of failure: a broken invariant is a bug, not an
// input error). Checked in every build type, NDEBUG or not: a violated one prints
//   chimera: invariant broken: Result::value() on an error (src/...:42)
// to stderr and aborts, so that it is caught where it happens instead of turning into a wrong
// result later. Real-time safe while it holds (one predictable branch); when it fails nothing is
// safe any more.
//
// Tests prove that a check fires either with a death test (the default handler aborts) or, where
// the check is not inside a noexcept function, by installing a handler that throws.

namespace chimera {

/// Called with the invariant's description and where it was checked. It must not return: if it
/// does, the process aborts anyway.
using InvariantHandler = void (*)(const char* what, const char* file, int line);

/// Installs `handler` (nullptr: the default, print and abort) for the whole process and returns
/// the previous one. For tests. Not real-time safe.
InvariantHandler set_invariant_handler(InvariantHandler handler) noexcept;

namespace detail {
[[noreturn]] void invariant_failed(const char* what, const char* file, int line);
}  // namespace detail

}  // namespace chimera

/// Checks `condition`, whatever the build type; `what` is a string literal naming the invariant.
#define CHIMERA_INVARIANT(condition, what) \
  ((condition) ? static_cast<void>(0) : ::chimera::detail::invariant_failed((what), __FILE__, __LINE__))
