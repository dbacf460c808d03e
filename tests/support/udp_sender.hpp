#pragma once
// Sends datagrams to a UDP port on loopback, for tests of modules whose resource port is a UDP
// socket (teleop_input, udp_command). On loopback a datagram is in the receiver's socket when
// send() returns, so a test on the virtual clock knows the next cycle reads it.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string_view>

namespace chimera::testing {

class UdpSender {
 public:
  explicit UdpSender(int port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    to_.sin_family = AF_INET;
    to_.sin_port = htons(static_cast<std::uint16_t>(port));
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~UdpSender() {
    if (fd_ >= 0) ::close(fd_);
  }
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;

  /// True if the whole datagram went out.
  bool send(std::string_view text) const {
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): the sockets API
    const auto* to = reinterpret_cast<const sockaddr*>(&to_);
    return fd_ >= 0 && ::sendto(fd_, text.data(), text.size(), 0, to, sizeof(to_)) == static_cast<ssize_t>(text.size());
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

}  // namespace chimera::testing
