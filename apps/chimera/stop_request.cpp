#include "stop_request.hpp"

#include <atomic>
#include <csignal>

namespace chimera::cli {

namespace {

// Lock-free, so it may be touched from a signal handler; global, because a handler reaches nothing else.
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): see above
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void on_stop_signal(int signo) {
  // relaxed: the flag carries no other data; the main loop only needs to see it eventually.
  if (g_stop.exchange(true, std::memory_order_relaxed)) {
    std::signal(signo, SIG_DFL);
    std::raise(signo);
  }
}

}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: interrupt poll() so the loop notices at once
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool stop_requested() { return g_stop.load(std::memory_order_relaxed); }

// relaxed: as the handler's store; the loop only needs to see it eventually.
void request_stop() { g_stop.store(true, std::memory_order_relaxed); }

}  // namespace chimera::cli
