#include "chimera/core/invariant.hpp"

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace chimera {

namespace {
// The process-wide handler; nullptr means print and abort.
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): the one hook a test may set
std::atomic<InvariantHandler> g_handler{nullptr};
}  // namespace

InvariantHandler set_invariant_handler(InvariantHandler handler) noexcept {
  // acq_rel: a handler installed by a test is seen whole by the thread whose check fails.
  return g_handler.exchange(handler, std::memory_order_acq_rel);
}

namespace detail {

void invariant_failed(const char* what, const char* file, int line) {
  // Acquire: pairs with set_invariant_handler's exchange.
  if (InvariantHandler handler = g_handler.load(std::memory_order_acquire); handler != nullptr)
    handler(what, file, line);
  // fprintf, not spdlog: this must work from any thread, in any state, without allocating.
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-vararg): see above
  std::fprintf(stderr, "chimera: invariant broken: %s (%s:%d)\n", what, file, line);
  std::fflush(stderr);
  std::abort();
}

}  // namespace detail
}  // namespace chimera
