// `--listen [ADDR:]PORT`: loopback unless asked, numeric addresses, ports 0 to 65535.

#include "chimera/net/listen_address.hpp"

#include <gtest/gtest.h>

namespace chimera::net {
namespace {

TEST(ListenAddress, APortAloneIsLoopback) {
  auto a = parse_listen_address("8080");
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_EQ(a->host, "127.0.0.1");
  EXPECT_EQ(a->port, 8080);
  EXPECT_TRUE(a->loopback);
  EXPECT_EQ(a->civetweb_ports(), "127.0.0.1:8080");
}

TEST(ListenAddress, AddressesSayWhetherOtherMachinesReachThem) {
  struct Case {
    const char* text;
    const char* host;
    int port;
    bool loopback;
    bool ipv6;
  };
  for (const Case& c :
       {Case{"127.0.0.1:0", "127.0.0.1", 0, true, false}, Case{"127.1.2.3:1", "127.1.2.3", 1, true, false},
        Case{"localhost:80", "127.0.0.1", 80, true, false}, Case{"0.0.0.0:8080", "0.0.0.0", 8080, false, false},
        Case{"192.168.1.5:65535", "192.168.1.5", 65535, false, false}, Case{"[::1]:8080", "::1", 8080, true, true},
        Case{"[::]:8080", "::", 8080, false, true}}) {
    auto a = parse_listen_address(c.text);
    ASSERT_TRUE(a) << c.text << ": " << a.error().message;
    EXPECT_EQ(a->host, c.host) << c.text;
    EXPECT_EQ(a->port, c.port) << c.text;
    EXPECT_EQ(a->loopback, c.loopback) << c.text;
    EXPECT_EQ(a->ipv6, c.ipv6) << c.text;
  }
  EXPECT_EQ(parse_listen_address("[::1]:80")->civetweb_ports(), "[::1]:80");
}

TEST(ListenAddress, BadTextIsOneLineNamingTheOption) {
  for (const char* bad : {"", "x", "-1", "65536", "8080x", "127.0.0.1:", "1.2.3:80", "example.com:80", "::1:80",
                          "[::1]", "[nonsense]:80", "127.0.0.1:80:90"}) {
    auto a = parse_listen_address(bad);
    ASSERT_FALSE(a) << bad;
    EXPECT_EQ(a.error().code, Errc::kInvalidInput);
    EXPECT_EQ(a.error().message.rfind("--listen '", 0), 0U) << a.error().message;
    EXPECT_EQ(a.error().message.find('\n'), std::string::npos) << a.error().message;
  }
}

}  // namespace
}  // namespace chimera::net
