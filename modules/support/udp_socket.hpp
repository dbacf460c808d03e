#pragma once
// A UDP socket for a module's resource port (udp_command, teleop_input): bound in init,
// non-blocking, so that a cycle may read it without ever waiting. Not real-time safe; the reads
// (recv with MSG_DONTWAIT) that modules make on it are.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <string>

namespace chimera::modules {

struct UdpSocket {
  int fd = -1;                  // -1 when binding failed
  int port = 0;                 // the port bound (the system's choice for port 0)
  const char* error = nullptr;  // why binding failed, a string literal
};

/// A non-blocking UDP socket bound to `address` (IPv4) and `port` (a parameter's value: a whole
/// number from 0 to 65535; 0 lets the system choose).
inline UdpSocket bind_udp(const std::string& address, double port) {
  UdpSocket s;
  if (!(port >= 0 && port <= 65535) || port != std::floor(port)) {
    s.error = "port must be a whole number from 0 to 65535";
    return s;
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::inet_pton(AF_INET, address.c_str(), &addr.sin_addr) != 1) {
    s.error = "address is not an IPv4 address";
    return s;
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    s.error = "cannot create a UDP socket";
    return s;
  }
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {  // NOLINT: the sockets API
    ::close(fd);
    s.error = "cannot bind the UDP socket (address in use?)";
    return s;
  }
  socklen_t length = sizeof(addr);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &length);  // NOLINT: the sockets API
  s.fd = fd;
  s.port = ntohs(addr.sin_port);
  return s;
}

}  // namespace chimera::modules
