// The paper's Figure 8 cut in two, as docs/dds.md cuts it: the vision subsystem and the robot
// side, each a real `chimera run` process, joined by Cyclone DDS (x_d one way, x_m the other).
// Once on one network stack, once on two: Linux network namespaces joined by a veth pair, made
// and removed by the test, so the samples cross a network link that the test can pull. Each time:
// the robot side alone holds the arm (its import is stale, the flag raised); with the vision side
// up the arm moves; the link pulled or the vision process killed, the arm is held again; the
// vision side brought back (the same subsystem, again), the arm moves again.
//
// Real clock, soft tasks (a shared machine's stalls are misses, not ERROR); every wait is bounded
// generously and ends as soon as what it waits for has happened. Nothing is timed.

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "chimera_process.hpp"
#include "run_chimera.hpp"

namespace chimera::test {
namespace {

const std::string kFlag = "illegal-configuration flag raised";
const std::string kInitial = "theta_m = [0.114, -0.254, 0.482, -0.081, 1.624, 0.077]\n";

bool eventually(const std::function<bool()>& condition, int seconds = 60) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return condition();
}

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (auto at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// Which names and partition this test process uses: no other test, here or in another process
// of this machine, shares them.
struct Names {
  std::string vision = "vision_side_" + std::to_string(::getpid());
  std::string robot = "robot_side_" + std::to_string(::getpid());
  std::string partition = "chimera_test_" + std::to_string(::getpid());
};

std::string vision_file(const Names& n) {
  return "subsystem: " + n.vision + R"(
tasks:
  - name: vision
    module: visual_servo
    period: 30ms
    criticality: soft
    params:
      center: [0.847, 0.10, 0.76, 0.0, 2.356, 0.0]
      amplitude: [0.075, 0.08, 0.03, 0.0, 0.0, 0.0]
      frequency: [0.1, 0.05, 0.15, 0.0, 0.0, 0.0]
      phase: [-1.5708, 1.5708, 1.5708, 0.0, 0.0, 0.0]
configurations:
  main: [vision]
start: main
exports: [x_d]
imports:
  x_m: { type: f64, count: 6, max_age: 500ms }
dds: { partition: )" +
         n.partition + " }\n";
}

std::string robot_file(const Names& n) {
  return "subsystem: " + n.robot + R"(
tasks:
  - { name: fk, module: fwd_kin_jacobian, period: 2ms, criticality: soft }
  - { name: ik, module: inv_kin, period: 2ms, criticality: soft }
  - name: robot
    module: robot_position
    period: 2ms
    criticality: soft
    params: { initial: [0.114, -0.254, 0.482, -0.081, 1.624, 0.077] }
configurations:
  main: [fk, ik, robot]
start: main
exports: [x_m]
imports:
  x_d: { type: f64, count: 6, max_age: 500ms }
dds: { partition: )" +
         n.partition + " }\n";
}

// One `chimera run` of a file, on the network stack its launcher puts it on.
struct Side {
  TempDir dir;
  std::unique_ptr<ChimeraProcess> process;

  Side(const std::string& name, const std::string& text, const std::vector<std::string>& launcher) {
    const std::string file = dir.file(name + ".yaml");
    write_text(file, text);
    process = std::make_unique<ChimeraProcess>(dir, std::vector<std::string>{"run", file}, std::vector<std::string>{},
                                               launcher);
  }

  [[nodiscard]] std::string err() const { return process->err(); }

  // The reply to `command`: `get VARIABLE` goes behind it, and its reply ends the first one's.
  std::string ask(const std::string& command, const std::string& variable = "theta_m") const {
    const std::size_t before = process->out().size();
    process->send(command + "\nget " + variable + "\n");
    std::string reply;
    eventually([&] {
      const std::string out = process->out();
      reply = out.size() > before ? out.substr(before) : std::string();
      // A variable no task has written yet has a reply of its own, which ends the wait as well.
      return (reply.find(variable + " = [") != std::string::npos && reply.ends_with("]\n")) ||
             reply.ends_with(variable + " has not been written yet\n");
    });
    return reply;
  }
  std::string get(const std::string& variable) const { return ask("# " + variable, variable); }
  std::string theta_m() const { return ask("# theta_m"); }
  bool flag_raised() const { return ask("status").find(kFlag) != std::string::npos; }
  // The words of `status`'s row for the import `variable` (its second table: import, state, from,
  // samples, refused, age, max_age; a duration is two words, "1.20 ms"); none if it has no such row.
  std::vector<std::string> import_row(const std::string& variable) const {
    const std::string status = ask("status");
    const auto table = status.find("\nimport ");
    if (table == std::string::npos) return {};
    const auto row = status.find("\n" + variable + " ", table + 1);
    if (row == std::string::npos) return {};
    std::istringstream line(status.substr(row + 1, status.find('\n', row + 1) - row - 1));
    std::vector<std::string> words;
    for (std::string w; line >> w;) words.push_back(w);
    return words;
  }

  // The arm holds: two readings of theta_m half a second apart differ by under a milliradian
  // (held in position mode, the simulated servo settles where the flag found the arm).
  bool holds() const {
    const std::vector<double> first = values(theta_m());
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    const std::vector<double> second = values(theta_m());
    if (first.size() != 6 || second.size() != 6) return false;
    for (std::size_t i = 0; i < 6; ++i)
      if (std::abs(first[i] - second[i]) > 1e-3) {
        ADD_FAILURE() << "joint " << i << " moved from " << first[i] << " to " << second[i] << " rad";
        return false;
      }
    return true;
  }

  // The numbers of a `get` reply, "NAME = [a, b, ...]".
  // True when `reply` holds six values, not all zero: an unwritten variable's reply holds none.
  static bool written_nonzero(const std::string& reply) {
    const std::vector<double> v = values(reply);
    return v.size() == 6 && v != std::vector<double>(6, 0.0);
  }

  static std::vector<double> values(const std::string& reply) {
    std::vector<double> out;
    const auto open = reply.find('[');
    if (open == std::string::npos) return out;
    const char* at = reply.c_str() + open + 1;
    char* end = nullptr;
    for (double v = std::strtod(at, &end); end != at; v = std::strtod(at, &end)) {
      out.push_back(v);
      at = end;
      while (*at == ',' || *at == ' ') ++at;
    }
    return out;
  }
};

// Two network namespaces joined by a veth pair, each with its end of the link and its loopback
// up, addresses only inside them; removed (with the link) by the destructor.
class NetworkPair {
 public:
  NetworkPair() {
    const std::string id = std::to_string(::getpid());
    vision_ns_ = "chimera_v" + id;
    robot_ns_ = "chimera_r" + id;
    vision_link_ = "chv" + id;  // an interface's name is at most 15 characters
    const std::string robot_link = "chr" + id;
    made_ = sh("ip netns add " + vision_ns_) && sh("ip netns add " + robot_ns_) &&
            sh("ip link add " + vision_link_ + " netns " + vision_ns_ + " type veth peer name " + robot_link +
               " netns " + robot_ns_) &&
            sh("ip -n " + vision_ns_ + " addr add 10.77.0.1/24 dev " + vision_link_) &&
            sh("ip -n " + robot_ns_ + " addr add 10.77.0.2/24 dev " + robot_link) &&
            sh("ip -n " + vision_ns_ + " link set lo up") && sh("ip -n " + robot_ns_ + " link set lo up") &&
            sh("ip -n " + robot_ns_ + " link set " + robot_link + " up") && link(true);
  }
  ~NetworkPair() {
    sh("ip netns del " + vision_ns_ + " 2>/dev/null");  // deleting a namespace deletes its veth end, and so the pair
    sh("ip netns del " + robot_ns_ + " 2>/dev/null");
  }
  NetworkPair(const NetworkPair&) = delete;
  NetworkPair& operator=(const NetworkPair&) = delete;

  [[nodiscard]] bool made() const { return made_; }
  [[nodiscard]] std::vector<std::string> vision_launcher() const { return {"ip", "netns", "exec", vision_ns_}; }
  [[nodiscard]] std::vector<std::string> robot_launcher() const { return {"ip", "netns", "exec", robot_ns_}; }
  // The vision machine's network cable, pulled (false) or plugged back in (true).
  bool link(bool up) { return sh("ip -n " + vision_ns_ + " link set " + vision_link_ + (up ? " up" : " down")); }

 private:
  // ip, on the test's own thread: nothing else calls system() or changes the environment meanwhile.
  static bool sh(const std::string& command) {
    return std::system(command.c_str()) == 0;  // NOLINT(cert-env33-c,concurrency-mt-unsafe)
  }

  bool made_ = false;
  std::string vision_ns_;
  std::string robot_ns_;
  std::string vision_link_;
};

// The whole story, on whichever network stacks the launchers give; with `network`, the link
// between them is also pulled and plugged back in.
void robot_holds_while_vision_is_away(const std::vector<std::string>& vision_launcher,
                                      const std::vector<std::string>& robot_launcher, NetworkPair* network) {
  const Names names;
  const std::string stale = "dds: import x_d: stale, no sample for ";
  const std::string fresh = "dds: import x_d: fresh again, from subsystem " + names.vision + "\n";

  // The robot side alone: nothing imported yet, the flag raised, the arm held.
  Side robot(names.robot, robot_file(names), robot_launcher);
  ASSERT_TRUE(eventually([&] {
    return robot.err().find("dds: import x_d: stale, no sample yet: the illegal-configuration flag is raised\n") !=
           std::string::npos;
  })) << robot.err();
  EXPECT_TRUE(robot.flag_raised());
  EXPECT_EQ(robot.theta_m(), kInitial);
  // `status` says so beside the tasks: stale, from nobody yet, no sample, no age.
  const std::vector<std::string> alone = robot.import_row("x_d");
  ASSERT_GE(alone.size(), 7U) << robot.ask("status");
  EXPECT_EQ(alone[1], "STALE");
  EXPECT_EQ(alone[2], "-");
  EXPECT_EQ(alone[3], "0");
  EXPECT_EQ(alone[5], "-");

  // The vision side up: x_d arrives, the flag comes down, the arm follows the target.
  auto vision = std::make_unique<Side>(names.vision, vision_file(names), vision_launcher);
  ASSERT_TRUE(eventually([&] {
    return robot.err().find("dds: import x_d: first sample, from subsystem " + names.vision + "\n") !=
               std::string::npos &&
           count(robot.err(), fresh) >= 1;
  })) << robot.err();
  ASSERT_TRUE(eventually([&] {
    return vision->err().find("dds: import x_m: first sample, from subsystem " + names.robot + "\n") !=
           std::string::npos;
  })) << vision->err();
  EXPECT_TRUE(eventually([&] { return !robot.flag_raised(); })) << robot.ask("status");
  EXPECT_TRUE(eventually([&] { return robot.theta_m() != kInitial; }));
  const std::vector<std::string> fed = robot.import_row("x_d");
  ASSERT_GE(fed.size(), 7U) << robot.ask("status");
  EXPECT_EQ(fed[1], "fresh");
  EXPECT_EQ(fed[2], names.vision);
  EXPECT_NE(fed[3], "0");
  EXPECT_EQ(fed[4], "0");
  EXPECT_NE(fed[5], "-");

  if (network != nullptr) {
    // The cable pulled: the import goes stale and the arm is held; plugged back in, it moves again.
    const std::size_t stale_before = count(robot.err(), stale);
    const std::size_t fresh_before = count(robot.err(), fresh);
    ASSERT_TRUE(network->link(false));
    ASSERT_TRUE(eventually([&] { return count(robot.err(), stale) > stale_before; })) << robot.err();
    EXPECT_TRUE(robot.flag_raised());
    EXPECT_TRUE(robot.holds());
    ASSERT_TRUE(network->link(true));
    ASSERT_TRUE(eventually([&] { return count(robot.err(), fresh) > fresh_before; })) << robot.err();
    EXPECT_TRUE(eventually([&] { return !robot.flag_raised(); })) << robot.ask("status");
  }

  // The vision process killed outright: stale again, the arm held, the robot side runs on.
  const std::size_t stale_before = count(robot.err(), stale);
  const std::size_t fresh_before = count(robot.err(), fresh);
  ASSERT_EQ(::kill(vision->process->pid(), SIGKILL), 0);
  EXPECT_EQ(vision->process->wait_exit(), -1);  // killed by a signal, as wait_exit() reports it
  vision.reset();
  ASSERT_TRUE(eventually([&] { return count(robot.err(), stale) > stale_before; })) << robot.err();
  EXPECT_TRUE(robot.flag_raised());
  EXPECT_TRUE(robot.holds());
  EXPECT_TRUE(robot.process->running());
  const std::vector<std::string> away = robot.import_row("x_d");
  ASSERT_GE(away.size(), 7U) << robot.ask("status");
  EXPECT_EQ(away[1], "STALE");
  EXPECT_EQ(away[2], names.vision);  // who fed it last

  // Brought back (its stale shared memory is no obstacle): fresh again, the flag down, the arm moving.
  vision = std::make_unique<Side>(names.vision, vision_file(names), vision_launcher);
  ASSERT_TRUE(eventually([&] { return count(robot.err(), fresh) > fresh_before; })) << robot.err() << vision->err();
  EXPECT_TRUE(eventually([&] { return !robot.flag_raised(); })) << robot.ask("status");
  const std::string moving = robot.theta_m();
  EXPECT_TRUE(eventually([&] { return robot.theta_m() != moving; }));

  vision->process->send("quit\n");
  EXPECT_EQ(vision->process->wait_exit(), 0) << vision->err();
  robot.process->send("quit\n");
  EXPECT_EQ(robot.process->wait_exit(), 0) << robot.err();
  EXPECT_EQ(robot.err().find("refused"), std::string::npos) << robot.err();
  EXPECT_EQ(robot.err().find("rule 1"), std::string::npos) << robot.err();
}

// The live assembly's add makes the vision side's table anew (a new region under the same name):
// its bridge follows it there, so that x_d from the new table reaches the robot side and x_m from
// the robot side reaches the new table. Before it did, the bridge stayed on the old region: the
// robot side's import stayed stale and the vision task read x_m that never came.
TEST(TwoSubsystems, TheBridgeFollowsTheTableThatAnAddMadeAnew) {
  const Names names;
  const std::string fresh = "dds: import x_d: fresh again, from subsystem " + names.vision + "\n";
  Side robot(names.robot, robot_file(names), {});
  Side vision(names.vision, vision_file(names), {});
  ASSERT_TRUE(eventually([&] {
    return robot.err().find("dds: import x_d: first sample, from subsystem " + names.vision + "\n") !=
           std::string::npos;
  })) << robot.err();
  std::string x_m_before;
  ASSERT_TRUE(eventually([&] { return Side::written_nonzero(x_m_before = vision.get("x_m")); }))
      << "x_m came before the add: " << x_m_before;

  // The vision task gone: the robot side's import goes stale; back after the add, fresh again.
  const std::size_t fresh_before = count(robot.err(), fresh);
  vision.process->send("kill vision\n");
  ASSERT_TRUE(eventually([&] {
    return robot.err().find("dds: import x_d: stale, no sample for ") != std::string::npos;
  })) << robot.err();
  vision.process->send("add {name: spare, module: cpu_load, period: 100ms, criticality: soft}\n");
  EXPECT_TRUE(eventually([&] { return vision.err().find("the bridge follows it") != std::string::npos; }, 10))
      << vision.err() << vision.process->out();
  // The new table's x_m is unwritten until the bridge writes it there: it does, from the robot.
  EXPECT_TRUE(eventually([&] { return Side::written_nonzero(vision.get("x_m")); })) << vision.get("x_m");
  vision.process->send("spawn vision\non vision\n");
  ASSERT_TRUE(eventually([&] { return count(robot.err(), fresh) > fresh_before; })) << robot.err() << vision.err();
  const std::string x_d = robot.get("x_d");
  EXPECT_TRUE(eventually([&] { return robot.get("x_d") != x_d; })) << "x_d from the new table moves";

  vision.process->send("quit\n");
  EXPECT_EQ(vision.process->wait_exit(), 0) << vision.err();
  robot.process->send("quit\n");
  EXPECT_EQ(robot.process->wait_exit(), 0) << robot.err();
}

// A run that starts without exports or imports, and opens the robot side's file: the bridge,
// idle until then, bridges that file's (x_d from the vision side arrives, x_m reaches it), under
// the opened file's subsystem name; opening a file without any stops it again.
TEST(TwoSubsystems, AFileOpenedWithImportsIsBridged) {
  const Names names;
  const std::string plain = "subsystem: plain_" + std::to_string(::getpid()) +
                            "\ntasks:\n  - {name: idle, module: cpu_load, period: 10ms, criticality: soft}\n";
  Side robot("plain", plain, {});
  const std::string robot_path = robot.dir.file(names.robot + ".yaml");
  write_text(robot_path, robot_file(names));
  Side vision(names.vision, vision_file(names), {});
  robot.process->send("open " + robot_path + "\n");
  ASSERT_TRUE(eventually([&] {
    return robot.err().find("dds: import x_d: first sample, from subsystem " + names.vision + "\n") !=
           std::string::npos;
  })) << robot.err()
      << robot.process->out();
  EXPECT_NE(robot.err().find("dds: the table was made anew (a task added, or a file opened): the bridge follows it"),
            std::string::npos)
      << robot.err();
  // The other way: x_m from the opened file's forward kinematics reaches the vision side.
  EXPECT_TRUE(eventually([&] { return Side::written_nonzero(vision.get("x_m")); }))
      << vision.get("x_m") << vision.err();

  const std::string plain_again = robot.dir.file("plain_again.yaml");
  write_text(plain_again, plain);
  robot.process->send("open " + plain_again + "\n");
  EXPECT_TRUE(eventually([&] {
    return robot.err().find("dds: the subsystem has no exports or imports now: the bridge stops") != std::string::npos;
  })) << robot.err();
  EXPECT_TRUE(eventually([&] {
    return vision.err().find("dds: import x_m: stale, no sample for ") != std::string::npos;
  })) << vision.err();

  vision.process->send("quit\n");
  EXPECT_EQ(vision.process->wait_exit(), 0) << vision.err();
  robot.process->send("quit\n");
  EXPECT_EQ(robot.process->wait_exit(), 0) << robot.err();
}

TEST(TwoSubsystems, TheRobotSideHoldsWhileTheVisionSideIsAwayOnOneNetworkStack) {
  robot_holds_while_vision_is_away({}, {}, nullptr);
}

// Needs root (CAP_SYS_ADMIN and CAP_NET_ADMIN) and iproute2, as the machines this project tests on
// have: without them the test fails and says so, it is not skipped.
TEST(TwoSubsystems, TheRobotSideHoldsWhileTheVisionSideIsAwayAcrossAVethLink) {
  NetworkPair network;
  ASSERT_TRUE(network.made()) << "could not make two network namespaces joined by a veth pair: this test needs "
                                 "root and iproute2 (ip netns)";
  robot_holds_while_vision_is_away(network.vision_launcher(), network.robot_launcher(), &network);
}

}  // namespace
}  // namespace chimera::test
