#pragma once
// Where the network control API listens: `--listen [ADDR:]PORT` (contract section 4), loopback
// unless another address is asked for.

#include <string>
#include <string_view>

#include "chimera/core/result.hpp"

namespace chimera::net {

struct ListenAddress {
  std::string host;  // a numeric address: "127.0.0.1", "0.0.0.0", "::1"
  int port = 0;      // 0: the system picks a free port (the server reports which)
  bool ipv6 = false;
  bool loopback = true;  // only this machine can connect

  /// The address as civetweb's listening_ports option writes it ("127.0.0.1:8080", "[::1]:8080").
  [[nodiscard]] std::string civetweb_ports() const;
  /// "127.0.0.1:8080", "[::1]:8080", with `port` in place of the asked one (the bound port).
  [[nodiscard]] std::string text(int bound_port) const;
};

/// Parses "PORT", "ADDR:PORT" or "[ADDR6]:PORT". ADDR is a numeric IPv4 or IPv6 address, or
/// "localhost" (127.0.0.1); PORT is 0 to 65535. Errors (Errc::kInvalidInput) are one line
/// starting with "--listen". Not real-time safe.
Result<ListenAddress> parse_listen_address(std::string_view text);

}  // namespace chimera::net
