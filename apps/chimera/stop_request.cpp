#include "stop_request.hpp"

#include <unistd.h>

#include <array>
#include <atomic>
#include <csignal>
#include <string_view>

#include "chimera/svt/global_table.hpp"

namespace chimera::cli {

namespace {

// Lock-free, so it may be touched from a signal handler; global, because a handler reaches nothing else.
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): see above
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);

constexpr std::array kStopSignals{SIGINT, SIGTERM, SIGHUP};

extern "C" void on_stop_signal(int signo) {
  // relaxed: the flag carries no other data; the main loop only needs to see it eventually.
  if (!g_stop.exchange(true, std::memory_order_relaxed)) return;
  // A second signal: the clean stop is too slow for whoever sends it, or stuck. End the default
  // way, but first take the shared memory's name away: no sequence of signals leaves it behind.
  GlobalTable::remove_owned_names_now();
  constexpr std::string_view kSaying = "chimera: a second signal: ending at once, without the clean stop\n";
  (void)::write(STDERR_FILENO, kSaying.data(), kSaying.size());
  std::signal(signo, SIG_DFL);
  std::raise(signo);
}

}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  // While one of them is being handled the others wait, so two handlers never interleave.
  for (const int signo : kStopSignals) sigaddset(&action.sa_mask, signo);
  action.sa_flags = 0;  // no SA_RESTART: interrupt poll() so the loop notices at once
  for (const int signo : kStopSignals) sigaction(signo, &action, nullptr);
  // A reader of stdout that went away (`chimera run ... | head`) must not end the run abruptly:
  // the write fails instead, and the run stops the ordinary way.
  std::signal(SIGPIPE, SIG_IGN);
}

bool stop_requested() { return g_stop.load(std::memory_order_relaxed); }

}  // namespace chimera::cli
