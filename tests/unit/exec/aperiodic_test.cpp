// Aperiodic tasks and sporadic servers on the virtual clock: a task without a period runs once
// per event of its trigger (a variable's update, a readable descriptor); a server bounds its
// share of the processor so that a flood of events never breaks a hard periodic task.

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/run_subsystem.hpp"
#include "support/trace_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

std::unique_ptr<Subsystem> start(const std::string& yaml) {
  return testing::start_subsystem(yaml, testing::scheduling_registry());
}

TaskStatsSnapshot stats_of(Subsystem& s, const std::string& task) { return testing::task_of(s, task).stats; }

/// A pipe whose read end the test hands to an fd_reader, filled with `bytes` bytes.
struct Pipe {
  int fds[2] = {-1, -1};
  explicit Pipe(int bytes) {
    EXPECT_EQ(::pipe2(fds, O_NONBLOCK), 0);
    const std::string data(static_cast<std::size_t>(bytes), 'x');
    EXPECT_EQ(::write(fds[1], data.data(), data.size()), bytes);
  }
  ~Pipe() {
    ::close(fds[0]);
    ::close(fds[1]);
  }
  Pipe(const Pipe&) = delete;
  Pipe& operator=(const Pipe&) = delete;
};

TEST(Aperiodic, AnUpdateTriggerRunsOneCyclePerNewValue) {
  auto s = start(
      "subsystem: a\ntasks:\n"
      "  - {name: c, module: counter, period: 10ms}\n"
      "  - {name: copier, module: update_copier, server: {budget: 1ms, period: 10ms}}\n");
  ASSERT_TRUE(s);
  s->run_for(105 * kMs);
  EXPECT_EQ(s->get("count")->at(0), 11.0);
  EXPECT_EQ(s->get("served")->at(0), 11.0) << "one cycle per update";
  EXPECT_EQ(s->get("seen")->at(0), 11.0) << "and it read the value that woke it";
  EXPECT_EQ(stats_of(*s, "copier").latency_max_ns, 0);
}

TEST(Aperiodic, TheOperatorsSetIsAnUpdateToo) {
  auto s = start(
      "subsystem: a\ntasks:\n"
      "  - {name: c, module: counter, period: 10ms}\n"
      "  - {name: copier, module: update_copier, server: {budget: 1ms, period: 10ms}}\n");
  ASSERT_TRUE(s);
  ASSERT_TRUE(s->signal("c", Signal::kOff).ok());  // the first cycle at 0 has run; count is free to set
  s->run_for(10 * kMs);
  const double served = s->get("served")->at(0);
  s->run_for(10 * kMs);
  EXPECT_EQ(s->get("served")->at(0), served) << "nothing new, nothing served";
  ASSERT_TRUE(s->set("count", {42}).ok());
  s->run_for(10 * kMs);
  EXPECT_EQ(s->get("served")->at(0), served + 1);
  EXPECT_EQ(s->get("seen")->at(0), 42.0);
}

TEST(Aperiodic, ASporadicServerBoundsAFloodAndTheHardTaskKeepsItsDeadlines) {
  // 1000 events waiting at once, each job 1 ms of simulated time, a server of 1 ms per 5 ms,
  // beside a hard 10 ms task of 7 ms: U = 0.7 + 0.2 = 0.9.
  Pipe flood(1000);
  auto s = start(
      "subsystem: a\ncpus: [0]\ntasks:\n"
      "  - {name: hard, module: cpu_load, period: 10ms, params: {exec: 0.007}}\n"
      "  - {name: reader, module: fd_reader, virtual_exec: 1ms, server: {budget: 1ms, period: 5ms}, "
      "params: {fd: " +
      std::to_string(flood.fds[0]) + "}}\n");
  ASSERT_TRUE(s);
  s->run_for(1000 * kMs);
  EXPECT_EQ(stats_of(*s, "hard").missed, 0u);
  EXPECT_EQ(stats_of(*s, "hard").cycles, 100u);
  const double served = s->get("bytes_read")->at(0);
  // One job per 5 ms period at most: 200 in a second.
  EXPECT_LE(served, 200.0);
  EXPECT_GE(served, 190.0);
}

TEST(Aperiodic, WithoutAServerItRunsInTheBackgroundOnly) {
  Pipe flood(1000);
  auto s = start(
      "subsystem: a\ncpus: [0]\ntasks:\n"
      "  - {name: hard, module: cpu_load, period: 10ms, params: {exec: 0.007}}\n"
      "  - {name: reader, module: fd_reader, virtual_exec: 1ms, params: {fd: " +
      std::to_string(flood.fds[0]) + "}}\n");
  ASSERT_TRUE(s);
  s->run_for(1005 * kMs);  // the 300th job ends at 1000 ms
  EXPECT_EQ(stats_of(*s, "hard").missed, 0u);
  // The 3 ms left of each 10 ms go to it: 300 events in a second.
  EXPECT_EQ(s->get("bytes_read")->at(0), 300.0);
}

TEST(Aperiodic, AUdpFloodCannotBreakAHard1kHzTask) {
  // The library's UDP command receiver under a server of 0.2 ms per 1 ms (50 us per datagram),
  // flooded with 10,000 datagrams, beside a hard 1 kHz task of 0.6 ms: U = 0.8.
  auto s = start(
      "subsystem: a\ncpus: [0]\ntasks:\n"
      "  - {name: control, module: cpu_load, frequency: 1kHz, params: {exec: 0.0006}}\n"
      "  - {name: commands, module: udp_command, server: {budget: 200us, period: 1ms}, "
      "params: {size: 2, cost: 0.00005}}\n");
  ASSERT_TRUE(s);
  const int port = static_cast<int>(s->get("udp_port")->at(0));
  ASSERT_GT(port, 0);
  const int out = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  int sent = 0;
  for (int i = 0; i < 10'000; ++i) {
    const std::string text = std::to_string(i) + " 1";
    // The socket's receive buffer holds a few hundred datagrams: what does not fit is dropped,
    // as a flood's would be. Send in bursts between stretches of simulated time.
    if (::sendto(out, text.data(), text.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof(to)) > 0) ++sent;
    if (i % 100 == 99) s->run_for(10 * kMs);
  }
  ::close(out);
  s->run_for(100 * kMs);
  const auto control = stats_of(*s, "control");
  EXPECT_EQ(control.missed, 0u);
  EXPECT_EQ(control.cycles, 1100u);
  const double accepted = s->get("command_stats")->at(0);
  EXPECT_GT(accepted, 0.0);
  // At most 4 datagrams (4 x 50 us = the 200 us budget) per 1 ms server period, in 1.1 s.
  EXPECT_LE(accepted, 4.0 * 1100);
  std::cout << "accepted " << accepted << " of " << sent << " datagrams sent\n";
  EXPECT_EQ(s->get("command_stats")->at(1), 0.0);
  EXPECT_GT(sent, 0);
}

}  // namespace
}  // namespace chimera
