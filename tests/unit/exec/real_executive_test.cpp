// The real clock: threads, absolute releases, signals through the mailbox, the data-flow rule
// with real threads. Behaviour only; timing figures live in the benchmarks.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/exec/clock.hpp"
#include "chimera/exec/write_watch.hpp"
#include "support/trace_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

std::unique_ptr<Subsystem> make(const std::string& tasks_yaml, const std::string& head = "") {
  testing::calls().clear();
  auto spec = load_subsystem_text("subsystem: realexec\n" + head + "tasks:\n" + tasks_yaml, "real.yaml",
                                  testing::scheduling_registry());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  RunOptions o;
  o.clock = ClockKind::kReal;
  o.shm_suffix = testing::unique_suffix();
  o.realtime_priorities = false;  // ordinary threads: the behaviour must not depend on SCHED_FIFO
  auto s = Subsystem::create(*spec, testing::scheduling_registry(), o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  return std::move(*s);
}

TEST(RealExecutive, RunsSignalsAndStopsCleanly) {
  // Soft tasks: a deadline missed on a loaded machine must not send them to ERROR here.
  auto s = make(
      "  - {name: c, module: counter, period: 2ms, criticality: soft}\n"
      "  - {name: p, module: probe, period: 2ms, criticality: soft}\n");
  ASSERT_TRUE(s->start().ok());
  s->run_for(100 * kMs);
  auto snap = s->snapshot();
  ASSERT_EQ(snap.size(), 2u);
  EXPECT_EQ(snap[0].state, TaskState::kOn);
  EXPECT_GT(snap[0].stats.cycles, 10u) << "the task cycles on its own thread";
  ASSERT_TRUE(s->signal("c", Signal::kOff).ok());
  const auto frozen = s->get("count")->at(0);
  s->run_for(200 * kMs);
  EXPECT_EQ(s->get("count")->at(0), frozen) << "an OFF task does not cycle";
  ASSERT_TRUE(s->signal("c", Signal::kOn).ok());
  s->run_for(200 * kMs);
  EXPECT_GT(s->get("count")->at(0), frozen);
  s->stop();
  EXPECT_EQ(testing::calls()["p"][testing::kOff], 1);
  EXPECT_EQ(testing::calls()["p"][testing::kKill], 1);
}

// The news is taken once, however often the producers publish before the watcher takes it;
// waiting returns at once while there is news not taken, else at the deadline.
TEST(WriteWatch, TakesTheNewsOnceAndWaitsOnlyWithoutIt) {
  WriteWatch watch;
  EXPECT_FALSE(watch.take());
  watch.written();
  watch.written();
  const std::int64_t t0 = monotonic_ns();
  watch.wait_until(t0 + 10'000'000'000);
  EXPECT_LT(monotonic_ns() - t0, 5'000'000'000) << "news not taken: the wait returns at once";
  EXPECT_TRUE(watch.take());
  EXPECT_FALSE(watch.take());
  const std::int64_t t1 = monotonic_ns();
  watch.wait_until(t1 + 20'000'000);
  EXPECT_GE(monotonic_ns() - t1, 20'000'000) << "no news: the wait lasts until its deadline";
}

// A producer on another thread wakes a watcher asleep with no deadline in sight, whichever of the
// two comes first; 200 rounds give the written() between the watcher's flag and its sleep a chance.
TEST(WriteWatch, AWriteFromAnotherThreadWakesTheSleepingWatcher) {
  WriteWatch watch;
  std::atomic<int> round{0};
  std::thread producer([&] {
    for (int r = 1; r <= 200; ++r) {
      while (round.load() < r) std::this_thread::yield();
      if (round.load() > 200) return;
      if (r % 2 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));  // after it sleeps
      watch.written();
    }
  });
  for (int r = 1; r <= 200; ++r) {
    round.store(r);
    const std::int64_t t0 = monotonic_ns();
    watch.wait_until(t0 + 60'000'000'000);
    const bool woken = monotonic_ns() - t0 < 30'000'000'000;
    EXPECT_TRUE(woken) << "round " << r << ": the write did not wake the watcher";
    if (!woken) break;  // the producer is stopped by the join's round below
    // a spurious wake may return before the news: then it comes in a later wait
    while (!watch.take()) watch.wait_until(monotonic_ns() + 60'000'000'000);
  }
  round.store(1000);
  producer.join();
}

// The DDS bridge's wake: a watched variable's producer rings the watch as it publishes, and
// only while it runs.
TEST(RealExecutive, AWatchedVariableWakesItsWatcherAsItsProducerPublishes) {
  auto s = make("  - {name: c, module: counter, period: 2ms, criticality: soft}\n");
  auto watch = std::make_shared<WriteWatch>();
  ASSERT_TRUE(s->watch_writes("count", watch).ok());
  const auto unknown = s->watch_writes("nosuch", watch);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().message, "no state variable named 'nosuch'");
  ASSERT_TRUE(s->start().ok());
  const auto woken_within = [&](std::int64_t ns) {
    const std::int64_t t0 = monotonic_ns();
    while (!watch->take()) {
      if (monotonic_ns() - t0 >= ns) return false;
      watch->wait_until(t0 + ns);
    }
    return true;
  };
  ASSERT_TRUE(woken_within(30'000'000'000)) << "no wake within 30 s";
  EXPECT_GE(s->get("count")->at(0), 1.0) << "what woke us is there to read";

  ASSERT_TRUE(s->signal("c", Signal::kOff).ok());
  (void)watch->take();  // a publication before the off took effect
  s->run_for(100 * kMs);
  EXPECT_FALSE(woken_within(20 * kMs)) << "an OFF task publishes nothing";
  ASSERT_TRUE(s->signal("c", Signal::kOn).ok());
  EXPECT_TRUE(woken_within(30'000'000'000)) << "no wake within 30 s after on";
  s->stop();
}

TEST(RealExecutive, AFailingTaskGoesToErrorAndTheOtherRunsOn) {
  auto s = make(
      "  - {name: c, module: counter, period: 2ms, criticality: soft}\n"
      // Hard, with a deadline no stall of a shared machine reaches: the test is about a method
      // failure, and a deadline miss on a loaded machine would send it to ERROR a cycle early.
      "  - {name: p, module: probe, period: 2ms, deadline: 500ms, params: {fail: cycle, fail_after: 3}}\n");
  ASSERT_TRUE(s->start().ok());
  s->run_for(200 * kMs);
  const auto before = s->get("count")->at(0);
  s->run_for(200 * kMs);
  auto snap = s->snapshot();
  EXPECT_EQ(snap[1].state, TaskState::kError);
  EXPECT_EQ(snap[1].stats.cycles, 4u);
  EXPECT_GT(s->get("count")->at(0), before);
  EXPECT_TRUE(s->hard_task_failed());
}

TEST(RealExecutive, SameRateConsumerLagsOnlyWhenItsProducerIsLatePastTheBound) {
  // The consumer is listed first and both threads are released at the same instants; the
  // precedence rule must order them. Without it, most cycles would lag. A shared machine may hold
  // the producer's thread past the bound (half the consumer's deadline), and the executive then
  // records that it gave up: every lagged cycle must be one of those, whatever the machine's load.
  auto s = make(
      "  - {name: f, module: follower, period: 5ms, criticality: soft, late: run}\n"
      "  - {name: c, module: counter, period: 5ms, criticality: soft, late: run}\n");
  ASSERT_TRUE(s->start().ok());
  s->run_for(500 * kMs);
  auto off_r = s->signal("f", Signal::kOff);
  ASSERT_TRUE(off_r.ok()) << off_r.error().message;
  const double cycles = s->get("follower_cycles")->at(0);
  const double lagged = s->get("lagged")->at(0);
  std::uint64_t gave_up = 0;
  for (const auto& t : s->snapshot())
    if (t.name == "f") gave_up = t.stats.order_timeouts;
  EXPECT_GT(cycles, 20);
  EXPECT_LE(lagged, static_cast<double>(gave_up)) << lagged << " of " << cycles << " cycles lagged";
}

// EDF and MUF run through the per-CPU priority dispatcher; the order it enforces is tested on the
// virtual clock and in priority_dispatcher_test. Here: the threads, pokes and signals work.
TEST(RealExecutive, EdfAndMufSubsystemsRunAndStopCleanly) {
  for (const char* scheduler : {"edf", "muf"}) {
    auto s = make(
        "  - {name: c, module: counter, period: 2ms, criticality: soft}\n"
        "  - {name: f, module: follower, period: 2ms, criticality: soft}\n"
        "  - {name: load, module: cpu_load, period: 5ms, criticality: soft, params: {exec: 0.0005}}\n",
        std::string("scheduler: ") + scheduler + "\n");
    ASSERT_TRUE(s->start().ok());
    s->run_for(100 * kMs);
    ASSERT_TRUE(s->signal("load", Signal::kOff).ok());
    for (const auto& t : s->snapshot()) EXPECT_GT(t.stats.cycles, 5u) << scheduler << " " << t.name;
    s->stop();
  }
}

// Polls `done` every 10 ms for up to 5 s: real threads on a loaded machine take their time.
template <class F>
bool eventually(Subsystem& s, F done) {
  for (int i = 0; i < 500; ++i) {
    if (done()) return true;
    s.run_for(10 * kMs);
  }
  return done();
}

TEST(RealExecutive, AnAperiodicTaskWakesOnItsProducersUpdates) {
  auto s = make(
      "  - {name: c, module: counter, period: 5ms, criticality: soft}\n"
      "  - {name: copier, module: update_copier, criticality: soft, server: {budget: 2ms, period: 5ms}}\n");
  ASSERT_TRUE(s->start().ok());
  ASSERT_TRUE(eventually(*s, [&] { return s->get("served")->at(0) >= 5; }));
  ASSERT_TRUE(s->signal("c", Signal::kOff).ok());
  // Updates that come faster than it runs are served once (the latest value is what counts), but
  // the last one is always served.
  EXPECT_TRUE(eventually(*s, [&] { return s->get("seen")->at(0) == s->get("count")->at(0); }));
  EXPECT_LE(s->get("served")->at(0), s->get("count")->at(0));
}

TEST(RealExecutive, AUdpCommandReceiverTakesEveryDatagram) {
  auto s = make("  - {name: commands, module: udp_command, criticality: soft, params: {size: 2}}\n");
  ASSERT_TRUE(s->start().ok());
  const int port = static_cast<int>(s->get("udp_port")->at(0));
  const int out = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  for (int i = 1; i <= 50; ++i) {
    const std::string text = std::to_string(i) + " -1";
    ASSERT_GT(::sendto(out, text.data(), text.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof(to)), 0);
  }
  const std::string bad = "not numbers";
  ASSERT_GT(::sendto(out, bad.data(), bad.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof(to)), 0);
  ::close(out);
  EXPECT_TRUE(eventually(*s, [&] { return s->get("command_stats")->at(1) == 1; }));
  EXPECT_EQ(s->get("command_stats")->at(0), 50.0);
  EXPECT_EQ(s->get("command")->at(0), 50.0);
  EXPECT_EQ(s->get("command")->at(1), -1.0);
  s->stop();  // the task sleeps in poll(); kill must still reach it
}

}  // namespace
}  // namespace chimera

namespace chimera {
namespace {

/// Waits up to `limit` for an event of `task` containing `text`; the events seen are kept in `seen`.
bool wait_for_event(Subsystem& s, const std::string& task, const std::string& text, std::vector<Event>& seen,
                    std::int64_t limit = 5'000 * kMs) {
  for (std::int64_t waited = 0; waited < limit; waited += 10 * kMs) {
    for (auto& e : s.drain_events()) seen.push_back(std::move(e));
    for (const auto& e : seen)
      if (e.task == task && e.text.find(text) != std::string::npos) return true;
    s.run_for(10 * kMs);
  }
  return false;
}

/// Lets every stuck Staller return when the test ends, passed or failed: declared after the
/// subsystem, so destroyed before it, whose stop() would otherwise wait for the stuck job forever.
struct ReleaseStallersAtExit {
  ReleaseStallersAtExit() { testing::stall_released().store(false, std::memory_order_relaxed); }  // no thread yet
  ~ReleaseStallersAtExit() {
    testing::stall_released().store(true, std::memory_order_release);
  }  // the staller's acquire
  ReleaseStallersAtExit(const ReleaseStallersAtExit&) = delete;
  ReleaseStallersAtExit& operator=(const ReleaseStallersAtExit&) = delete;
};

std::size_t count_events(const std::vector<Event>& seen, const std::string& task, const std::string& text) {
  return static_cast<std::size_t>(std::count_if(seen.begin(), seen.end(), [&](const Event& e) {
    return e.task == task && e.text.find(text) != std::string::npos;
  }));
}

TEST(OverrunWatch, AHardJobStuckInCycleIsReportedWhileItLastsAndKeepsTheFlagUp) {
  auto s = make(
      "  - {name: stuck, module: staller, period: 10ms, params: {stall_at: 3}}\n"
      // Another period: under rm, tasks of one CPU and one period share a thread, and a stuck
      // job holds up the ones after it on its thread.
      "  - {name: c, module: counter, period: 20ms, criticality: soft}\n");
  const ReleaseStallersAtExit release_at_exit;
  ASSERT_TRUE(s->start().ok());
  std::vector<Event> seen;
  ASSERT_TRUE(wait_for_event(*s, "stuck", "still running", seen)) << "no report while the job is stuck";
  EXPECT_NE(seen.back().text.find("illegal-configuration flag is up"), std::string::npos) << seen.back().text;
  // While it lasts: the flag is up, the task is still ON (its error() cannot run inside cycle()),
  // and the other task runs on.
  EXPECT_TRUE(s->illegal_configuration());
  auto snap = s->snapshot();
  EXPECT_EQ(snap[0].state, TaskState::kOn);
  const auto counted = s->get("count")->at(0);
  s->run_for(100 * kMs);
  EXPECT_GT(s->get("count")->at(0), counted) << "the other task stops with the stuck one";
  EXPECT_EQ(count_events(seen, "stuck", "still running"), 1u) << "one report per stuck job";
  EXPECT_TRUE(s->illegal_configuration());

  // Released: the job ends late, a hard task's miss: error() does not recover, so ERROR (and the
  // flag stays up for that reason).
  testing::stall_released().store(true, std::memory_order_release);  // release: the staller's acquire
  ASSERT_TRUE(wait_for_event(*s, "stuck", "ERROR", seen));
  for (auto& e : s->drain_events()) seen.push_back(std::move(e));
  EXPECT_EQ(count_events(seen, "stuck", "still running"), 1u);
  EXPECT_EQ(s->snapshot()[0].state, TaskState::kError);
  EXPECT_TRUE(s->illegal_configuration());
  s->stop();
}

TEST(OverrunWatch, TheFlagGoesDownWhenAStuckHardJobEndsAndItsTaskRecovers) {
  auto s = make("  - {name: stuck, module: staller, period: 10ms, params: {stall_at: 2, recover: true}}\n");
  const ReleaseStallersAtExit release_at_exit;
  ASSERT_TRUE(s->start().ok());
  std::vector<Event> seen;
  ASSERT_TRUE(wait_for_event(*s, "stuck", "still running", seen));
  EXPECT_TRUE(s->illegal_configuration());
  testing::stall_released().store(true, std::memory_order_release);  // release: the staller's acquire
  bool lowered = false;
  for (int i = 0; i < 500 && !lowered; ++i) {
    s->run_for(10 * kMs);
    lowered = !s->illegal_configuration();
  }
  EXPECT_TRUE(lowered) << "the flag stayed up after the job ended and error() recovered";
  EXPECT_EQ(s->snapshot()[0].state, TaskState::kOn);
  EXPECT_GT(s->snapshot()[0].stats.missed, 0u) << "the late job is a counted miss";
  s->stop();
}

TEST(OverrunWatch, ASoftJobStuckInCycleIsReportedWithoutTheFlag) {
  auto s = make("  - {name: stuck, module: staller, period: 10ms, criticality: soft, params: {stall_at: 2}}\n");
  const ReleaseStallersAtExit release_at_exit;
  ASSERT_TRUE(s->start().ok());
  std::vector<Event> seen;
  ASSERT_TRUE(wait_for_event(*s, "stuck", "still running", seen));
  EXPECT_NE(seen.back().text.find("Soft"), std::string::npos) << seen.back().text;
  EXPECT_FALSE(s->illegal_configuration());
  testing::stall_released().store(true, std::memory_order_release);  // release: the staller's acquire
  s->stop();
}

}  // namespace
}  // namespace chimera
