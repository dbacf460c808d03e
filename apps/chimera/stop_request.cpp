#include "stop_request.hpp"

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <csignal>
#include <cstdint>
#include <string_view>

#include "chimera/svt/global_table.hpp"

namespace chimera::cli {

namespace {

// The first stop request's time on CLOCK_MONOTONIC, 0 until one arrives: the flag and the time
// in one atomic, because the stop signals may be handled on two threads at once (each handler
// blocks the others only on its own thread), and a second handler that saw a flag without its
// time would take a request repeated within the grace for one after it. Lock-free, so a handler
// may touch it; global, because a handler reaches nothing else. A request repeated within kGrace
// (timeout(1) signals the child and then its whole group; a service manager may do the same) is
// the same request.
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): see above
std::atomic<std::int64_t> g_first_ns{0};
static_assert(std::atomic<std::int64_t>::is_always_lock_free);
constexpr std::int64_t kGraceNs = 1'000'000'000;

constexpr std::array kStopSignals{SIGINT, SIGTERM, SIGHUP};

std::int64_t monotonic_now_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);  // async-signal-safe
  // Never 0 (the clock counts from boot), so 0 can mean "no request yet"; max() makes sure.
  return std::max<std::int64_t>(1, static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
}

// Records the first request and returns 0, or returns the first one's time when there was one.
std::int64_t note_request(std::int64_t now_ns) {
  std::int64_t first_ns = 0;
  // relaxed: the value carries no other data; the main loop only needs to see it eventually.
  if (g_first_ns.compare_exchange_strong(first_ns, now_ns, std::memory_order_relaxed)) return 0;
  return first_ns;
}

extern "C" void on_stop_signal(int signo) {
  const std::int64_t now_ns = monotonic_now_ns();
  const std::int64_t first_ns = note_request(now_ns);
  if (first_ns == 0 || now_ns - first_ns < kGraceNs) return;
  // Asked again after the grace: the clean stop is stuck, or too slow for whoever asks. End the
  // default way, but first take the shared memory's name away: no sequence of signals leaves it.
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

// relaxed: as note_request's exchange; the loop only needs to see it eventually.
bool stop_requested() { return g_first_ns.load(std::memory_order_relaxed) != 0; }

// A signal within the grace after it is the same request, as after a signal.
void request_stop() { (void)note_request(monotonic_now_ns()); }

}  // namespace chimera::cli
