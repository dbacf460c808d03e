// scripts/chimera-teleop, the operator's side: what it sends for a command, keys and a recorded
// session, what it records, and what it refuses. A socket of the test's own stands in for
// teleop_input.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "run_chimera.hpp"

namespace chimera::test {
namespace {

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

class TeleopSenderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    ASSERT_GE(fd_, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): the sockets API
    ASSERT_EQ(::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
    socklen_t length = sizeof(addr);
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): the sockets API
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &length);
    port_ = ntohs(addr.sin_port);
  }
  void TearDown() override { ::close(fd_); }

  // `chimera-teleop --port P <args>` with `input` on standard input.
  Outcome sender(const std::string& args, const std::string& input = {}) {
    const std::string in = dir_.file("in.txt");
    write_text(in, input);
    const std::string out = dir_.file("out.txt");
    const std::string err = dir_.file("err.txt");
    const std::string command = "/usr/bin/python3 " + quoted(CHIMERA_TELEOP) + " --port " + std::to_string(port_) +
                                " " + args + " <" + quoted(in) + " >" + quoted(out) + " 2>" + quoted(err);
    const int status = std::system(command.c_str());  // NOLINT(concurrency-mt-unsafe): tests run one thread
    return Outcome{WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(out), read_text(err)};
  }

  // The datagrams that have arrived (they are all there when the sender has exited).
  std::vector<std::string> received() const {
    std::vector<std::string> out;
    std::array<char, 512> buffer{};
    pollfd p{fd_, POLLIN, 0};
    while (::poll(&p, 1, 0) == 1) {
      const ssize_t n = ::recv(fd_, buffer.data(), buffer.size(), 0);
      if (n < 0) break;
      out.emplace_back(buffer.data(), static_cast<std::size_t>(n));
    }
    return out;
  }

  TempDir dir_;
  int fd_ = -1;
  int port_ = 0;
};

TEST_F(TeleopSenderTest, SendsOneCommand) {
  EXPECT_EXIT_CODE(sender("move 0.05 -0.02 0"), 0);
  EXPECT_EQ(received(), (std::vector<std::string>{"move 0.05 -0.02 0"}));
}

TEST_F(TeleopSenderTest, RefusesWhatTeleopInputWouldRefuse) {
  for (const char* bad : {"jump 1 2 3", "move 1 2", "goto 1 2 3", "move 1 x 3"}) {
    const auto o = sender(bad);
    EXPECT_EXIT_CODE(o, 2);
    EXPECT_TRUE(o.err.starts_with("chimera-teleop: ")) << o.err;
  }
  EXPECT_TRUE(received().empty());
}

TEST_F(TeleopSenderTest, KeysBecomeStepsAndTheRecordReplays) {
  const std::string record = dir_.file("session.txt");
  EXPECT_EXIT_CODE(sender("--keys --step 0.02 --turn 0.1 --record " + quoted(record), "wwdx]u 0hq"), 0);
  const std::vector<std::string> sent{"move 0.02 0 0", "move 0.02 0 0", "move 0 -0.02 0", "move 0 0 0 0 0 0.2", "stop",
                                      "home",          "hold"};
  EXPECT_EQ(received(), sent) << "x is no key; ] doubled the steps";

  // The record is a session: `seconds command`, and sent again as it was.
  std::ifstream in(record);
  std::vector<std::string> commands;
  for (std::string line; std::getline(in, line);) {
    const auto space = line.find(' ');
    ASSERT_NE(space, std::string::npos) << line;
    EXPECT_GE(std::stod(line.substr(0, space)), 0.0) << line;
    commands.push_back(line.substr(space + 1));
  }
  EXPECT_EQ(commands, sent);
  EXPECT_EXIT_CODE(sender("--replay " + quoted(record) + " --speed 100"), 0);
  EXPECT_EQ(received(), sent);
}

TEST_F(TeleopSenderTest, AReplayNamesTheBadLine) {
  write_text(dir_.file("bad.txt"), "# a session\n0 move 0.01 0 0\n0.5 jump\n");
  const auto o = sender("--replay " + quoted(dir_.file("bad.txt")));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_EQ(o.err, "chimera-teleop: " + dir_.file("bad.txt") +
                       ":3: 'jump' is not a command (commands: move, goto, vel, stop, hold, home)\n");
  EXPECT_TRUE(received().empty()) << "nothing is sent from a session with a bad line";
}

TEST_F(TeleopSenderTest, LinesFromStandardInput) {
  EXPECT_EXIT_CODE(sender("--lines", "move 0.01 0 0\n# note\n\nnonsense\nvel 0.1 0 0\n"), 0);
  EXPECT_EQ(received(), (std::vector<std::string>{"move 0.01 0 0", "vel 0.1 0 0"}));
}

}  // namespace
}  // namespace chimera::test
