#include "chimera/net/listen_address.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <charconv>

#include <fmt/format.h>

namespace chimera::net {

namespace {

Error bad(std::string_view text, std::string_view why) {
  return Error{Errc::kInvalidInput, fmt::format("--listen '{}': {}", text, why)};
}

}  // namespace

std::string ListenAddress::civetweb_ports() const { return text(port); }

std::string ListenAddress::text(int bound_port) const {
  return ipv6 ? fmt::format("[{}]:{}", host, bound_port) : fmt::format("{}:{}", host, bound_port);
}

Result<ListenAddress> parse_listen_address(std::string_view text) {
  ListenAddress address;
  address.host = "127.0.0.1";
  std::string_view port_text = text;
  if (const auto colon = text.rfind(':'); colon != std::string_view::npos) {
    std::string_view host = text.substr(0, colon);
    port_text = text.substr(colon + 1);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
      host = host.substr(1, host.size() - 2);
      address.ipv6 = true;
    } else if (host.find(':') != std::string_view::npos) {
      return bad(text, "an IPv6 address goes in brackets, e.g. [::1]:8080");
    }
    if (host == "localhost" && !address.ipv6) host = "127.0.0.1";
    address.host = std::string(host);
  }
  if (port_text.empty()) return bad(text, "no port (PORT or ADDR:PORT, e.g. 8080 or 127.0.0.1:8080)");
  const char* end = port_text.data() + port_text.size();
  const auto [ptr, ec] = std::from_chars(port_text.data(), end, address.port);
  if (ec != std::errc{} || ptr != end || address.port < 0 || address.port > 65535)
    return bad(text, fmt::format("'{}' is not a port (0 to 65535)", port_text));

  if (address.ipv6) {
    in6_addr a6{};
    if (inet_pton(AF_INET6, address.host.c_str(), &a6) != 1)
      return bad(text, fmt::format("'{}' is not a numeric IPv6 address", address.host));
    address.loopback = IN6_IS_ADDR_LOOPBACK(&a6);
  } else {
    in_addr a4{};
    if (inet_pton(AF_INET, address.host.c_str(), &a4) != 1)
      return bad(text, fmt::format("'{}' is not a numeric IPv4 address (or localhost)", address.host));
    address.loopback = (ntohl(a4.s_addr) >> 24) == 127;  // 127.0.0.0/8
  }
  return address;
}

}  // namespace chimera::net
