#include "stop_request.hpp"

#include <time.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <csignal>
#include <cstdint>
#include <string_view>

#include "chimera/svt/global_table.hpp"

namespace chimera::cli {

namespace {

// Lock-free, so it may be touched from a signal handler; global, because a handler reaches nothing else.
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): see above
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);

constexpr std::array kStopSignals{SIGINT, SIGTERM, SIGHUP};

// The first stop request's time: a request repeated within kGrace (timeout(1) signals the
// child and then its whole group; a service manager may do the same) is the same request.
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): see g_stop
std::atomic<std::int64_t> g_first_ns{0};
static_assert(std::atomic<std::int64_t>::is_always_lock_free);
constexpr std::int64_t kGraceNs = 1'000'000'000;

std::int64_t monotonic_now_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);  // async-signal-safe
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

extern "C" void on_stop_signal(int signo) {
  // relaxed: the flag carries no other data; the main loop only needs to see it eventually.
  if (!g_stop.exchange(true, std::memory_order_relaxed)) {
    g_first_ns.store(monotonic_now_ns(), std::memory_order_relaxed);  // read only by this handler
    return;
  }
  if (monotonic_now_ns() - g_first_ns.load(std::memory_order_relaxed) < kGraceNs) return;
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

bool stop_requested() { return g_stop.load(std::memory_order_relaxed); }

// relaxed: as the handler's store; the loop only needs to see it eventually.
void request_stop() { g_stop.store(true, std::memory_order_relaxed); }

}  // namespace chimera::cli
