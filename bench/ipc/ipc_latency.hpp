#pragma once
// The latest value from one process to another, the same way for every transport: the
// publisher (a child process) publishes a message of six doubles at 1 kHz on an absolute-time
// grid, stamping CLOCK_MONOTONIC just before the publish call; the subscriber (the parent)
// polls for the newest value and records now - stamp for every message it sees.
//
// Both run SCHED_FIFO (as a control task would), each pinned to its own CPU. So as not to hog
// a shared CPU, the subscriber sleeps until shortly before the next message is due (the grid is
// in the message) and polls from there: what is measured is the transport, not a wake-up, and
// the same for all transports. Threads a transport makes (Cyclone DDS's receive thread) are
// created before the pinning, with the same priority and any CPU.
//
// A transport provides two classes, each built in its own process after the fork:
//   struct Pub { bool ready();  void publish(const Message&); };   // ready: a subscriber is matched
//   struct Sub { bool take_latest(Message&); };                    // false: nothing new
// and run_ipc_latency<Pub, Sub>() does the rest.

#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/bench_util.hpp"

namespace chimera::bench {

/// The payload: a joint-space vector (six doubles, like Figure 4's theta_m) with its stamps.
struct Message {
  std::uint64_t seq = 0;        // 1, 2, ...: tells a new message from one seen before
  std::int64_t stamp_ns = 0;    // just before the publish call
  std::int64_t release_ns = 0;  // the publisher's grid instant for this message
  std::array<double, 6> value{};
};

struct IpcPlan {
  int messages = 10'000;
  std::int64_t period_ns = 1'000'000;     // 1 kHz, a control rate
  std::int64_t poll_before_ns = 200'000;  // the subscriber polls from this long before a release
  int warmup = 200;                       // first messages not recorded
  int publisher_cpu = 0;
  int subscriber_cpu = 1;
  int priority = 70;                               // SCHED_FIFO, below Chimera's task threads (80)
  std::int64_t ready_timeout_ns = 10'000'000'000;  // discovery (DDS) may take a while
};

inline IpcPlan plan_for(const Args& args) {
  IpcPlan p;
  if (args.quick) p.messages = 2'000;
  return p;
}

struct IpcRun {
  std::vector<std::uint32_t> ns;
  int seen = 0;
  int missed = 0;  // messages overwritten before the subscriber saw them
  bool realtime = false;
  bool ok = false;
  std::string error;
};

inline bool set_fifo(int priority) {
  sched_param sp{};
  sp.sched_priority = priority;
  return sched_setscheduler(0, SCHED_FIFO, &sp) == 0;
}

inline void sleep_until(std::int64_t t) {
  const timespec ts{static_cast<time_t>(t / 1'000'000'000), static_cast<long>(t % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

namespace detail {

template <class Pub>
[[noreturn]] void publisher_main(const IpcPlan& plan, int go_fd,
                                 const std::function<std::unique_ptr<Pub>()>& make_pub) {
  char byte = 0;
  if (::read(go_fd, &byte, 1) != 1) ::_exit(3);  // the subscriber gave up
  auto pub = make_pub();
  if (!pub) ::_exit(4);
  const std::int64_t give_up = monotonic_ns() + plan.ready_timeout_ns;
  while (!pub->ready()) {
    if (monotonic_ns() > give_up) ::_exit(5);
    ::usleep(1000);
  }
  ::usleep(200'000);  // let the subscriber side settle (DDS: its reader's matching)
  pin_to_cpu(plan.publisher_cpu);
  Message m;
  std::int64_t next = monotonic_ns() + plan.period_ns;
  const int total = plan.warmup + plan.messages;
  for (int i = 1; i <= total; ++i) {
    sleep_until(next);
    m.seq = static_cast<std::uint64_t>(i);
    m.release_ns = next;
    m.value[0] = static_cast<double>(i);
    m.stamp_ns = monotonic_ns();
    pub->publish(m);
    next += plan.period_ns;
  }
  ::usleep(100'000);  // keep the publisher alive while the last message travels
  pub.reset();
  std::exit(0);  // not _exit: a transport's runtime (iceoryx) deregisters in static destructors
}

}  // namespace detail

/// Forks the publisher, runs the subscriber here. `make_pub` / `make_sub` build the transport
/// in their own process (after the fork); the pipe tells the publisher to start once the
/// subscriber exists.
template <class Pub, class Sub>
IpcRun run_ipc_latency(const IpcPlan& plan, const std::function<std::unique_ptr<Pub>()>& make_pub,
                       const std::function<std::unique_ptr<Sub>()>& make_sub) {
  IpcRun run;
  // Before the fork and before any transport thread exists: all of them inherit the policy.
  run.realtime = set_fifo(plan.priority);
  std::array<int, 2> go{};
  if (::pipe(go.data()) != 0) {
    run.error = "pipe failed";
    return run;
  }
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child < 0) {
    run.error = "fork failed";
    return run;
  }
  if (child == 0) {
    ::close(go[1]);
    detail::publisher_main<Pub>(plan, go[0], make_pub);
  }
  ::close(go[0]);
  auto sub = make_sub();
  if (!sub) {
    ::close(go[1]);
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    run.error = "subscriber set-up failed";
    return run;
  }
  pin_to_cpu(plan.subscriber_cpu);  // the transport's own threads keep any CPU
  const char byte = 1;
  if (::write(go[1], &byte, 1) != 1) run.error = "pipe write failed";
  ::close(go[1]);

  const auto last = static_cast<std::uint64_t>(plan.warmup + plan.messages);
  const std::int64_t deadline =
      monotonic_ns() + plan.ready_timeout_ns + 2 * plan.period_ns * static_cast<std::int64_t>(last);
  run.ns.reserve(static_cast<std::size_t>(plan.messages));
  std::uint64_t prev = 0;
  std::int64_t next_release = 0;  // unknown until the first message
  Message m;
  int status = 0;
  bool child_done = false;
  std::int64_t child_exit_ns = 0;
  while (run.error.empty()) {
    if (next_release != 0) sleep_until(next_release - plan.poll_before_ns);
    // Poll until a new message, for at most two periods (then a message was lost or is late).
    const std::int64_t poll_end = monotonic_ns() + 2 * plan.period_ns + plan.poll_before_ns;
    bool got = false;
    for (std::uint32_t polls = 0;; ++polls) {
      if (sub->take_latest(m) && m.seq != prev) {
        got = true;
        break;
      }
      if ((polls & 0xff) == 0 && monotonic_ns() > poll_end) break;
    }
    if (got) {
      const std::int64_t now = monotonic_ns();
      if (m.seq > static_cast<std::uint64_t>(plan.warmup)) {
        run.ns.push_back(static_cast<std::uint32_t>(std::min<std::int64_t>(now - m.stamp_ns, 4'000'000'000)));
        ++run.seen;
        if (prev >= static_cast<std::uint64_t>(plan.warmup)) run.missed += static_cast<int>(m.seq - prev - 1);
      }
      prev = m.seq;
      next_release = m.release_ns + plan.period_ns;
      if (m.seq >= last) break;
      continue;
    }
    next_release = 0;  // lost track of the grid: poll continuously until the next message
    if (monotonic_ns() > deadline) run.error = "timed out waiting for the publisher";
    if (!child_done && ::waitpid(child, &status, WNOHANG) == child) {
      child_done = true;
      child_exit_ns = monotonic_ns();
      if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        run.error = "publisher failed (exit " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
    }
    if (child_done && monotonic_ns() - child_exit_ns > 100'000'000) break;  // the last message was lost
  }
  if (!child_done) {
    if (!run.error.empty()) ::kill(child, SIGKILL);
    ::waitpid(child, &status, 0);
  }
  run.ok = run.error.empty() && run.seen > 0;
  return run;
}

/// Cyclone DDS on the loopback interface only, with unicast discovery: the VM's own network, and
/// any other DDS program on it, stay out of the measurement. Before the first participant.
inline void use_cyclone_dds_on_loopback() {
  ::setenv("CYCLONEDDS_URI",  // NOLINT(concurrency-mt-unsafe): before any thread
           "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
           "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
           "<MaxAutoParticipantIndex>30</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers>"
           "</Discovery></Domain></CycloneDDS>",
           1);
}

/// Writes the run as a fragment: keys PREFIX_latency_ns_p50 and PREFIX_latency_ns_p99.
inline int report_ipc(const Args& args, const std::string& prefix, const std::string& what, IpcRun& run,
                      const IpcPlan& plan) {
  Fragment out;
  auto& d = out.details()[prefix];
  d["transport"] = what;
  d["rate_hz"] = 1e9 / static_cast<double>(plan.period_ns);
  d["sched_fifo"] = run.realtime;
  d["messages_sent"] = plan.messages;
  d["messages_seen"] = run.seen;
  d["messages_missed"] = run.missed;
  if (!run.ok) {
    d["error"] = run.error;
    std::fprintf(stderr, "%s: %s\n", prefix.c_str(), run.error.c_str());
    (void)out.write(args);
    return 1;
  }
  out.samples(args, "ipc_" + prefix, run.ns);
  d["latency_ns"] = summary(run.ns);
  out.result(prefix + "_latency_ns_p50", d["latency_ns"]["p50"].get<double>());
  out.result(prefix + "_latency_ns_p99", d["latency_ns"]["p99"].get<double>());
  return out.write(args);
}

}  // namespace chimera::bench
