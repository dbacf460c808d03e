// udp_command: an aperiodic task whose resource port is a UDP socket. Each datagram is one event:
// the framework wakes the task when the socket is readable, sync() takes one datagram, cycle()
// publishes the numbers it holds. Run it under a sporadic server (`server:` in the file) so that
// a flood of datagrams can never take more than its share of the processor.

#include "module_docs/udp_command.hpp"

#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>

#include "chimera/module/registry.hpp"
#include "support/udp_socket.hpp"

namespace chimera::modules {
namespace {

constexpr double kDefaultSize = 6;
constexpr int kMaxSize = 256;

std::uint32_t size_of(const Params& p) {
  const double n = p.number("size", kDefaultSize);
  if (!(n >= 1) || n > kMaxSize) return static_cast<std::uint32_t>(kDefaultSize);
  return static_cast<std::uint32_t>(std::lround(n));
}

class UdpCommand final : public Module {
 public:
  static constexpr const char* kName = "udp_command";
  static constexpr const char* kSummary = docs::udp_command::kSummary;
  static constexpr const char* kDoc = docs::udp_command::kText;

  static void declare(Declarations& d, const Params& p) {
    const std::uint32_t n = size_of(p);
    d.out_var("command", Dim::fixed(n), "the numbers of the last accepted datagram");
    d.out_var("command_stats", Dim::fixed(2), "[datagrams accepted, datagrams rejected]");
    d.out_var("udp_port", Dim::fixed(1), "the UDP port the socket is bound to");
    d.param("address", std::string("127.0.0.1"), "", "IPv4 address to bind");
    d.param("port", 0.0, "", "UDP port to bind (0: the system chooses; see udp_port)")
        .whole()
        .at_least(0)
        .at_most(65535);
    d.param("size", kDefaultSize, "", "numbers per datagram").whole().at_least(1).at_most(256);
    d.param("cost", 0.0, "s", "simulated execution time per datagram on the virtual clock").at_least(0);
    d.resource("a UDP socket: each datagram is one event");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    const double size = p.number("size", kDefaultSize);
    if (!(size >= 1 && size <= kMaxSize) || size != std::floor(size))
      return ctx.refuse("size", "udp_command: size must be a whole number from 1 to 256");
    const double cost = p.number("cost");
    if (!(cost >= 0)) return ctx.refuse("cost", "udp_command: cost must be >= 0 s");
    cost_ns_ = static_cast<std::int64_t>(std::llround(cost * 1e9));

    const UdpSocket socket = bind_udp(p.text("address", "127.0.0.1"), p.number("port"));
    if (socket.fd < 0) return ctx.refuse("port", socket.error);
    fd_ = socket.fd;

    command_ = ctx.out<double>("command");
    stats_ = ctx.out<double>("command_stats");
    udp_port_ = ctx.out<double>("udp_port");
    if (ctx.failed()) return Status::ok();
    udp_port_[0] = socket.port;
    timing_ = &ctx.timing();
    ctx.trigger_on_fd(fd_);
    return Status::ok();
  }

  // One datagram per event: the socket stays readable while more wait, so the next one is
  // another event, which the server's budget may defer.
  Status sync() override {
    const ssize_t n = ::recv(fd_, buffer_.data(), buffer_.size() - 1, 0);
    length_ = n > 0 ? static_cast<std::size_t>(n) : 0;
    return Status::ok();
  }

  Status cycle() override {
    if (timing_->virtual_clock) consume_virtual_time(cost_ns_);
    if (length_ == 0) return Status::ok();
    std::array<double, kMaxSize> values{};
    std::size_t count = 0;
    const char* p = buffer_.data();
    const char* end = p + length_;
    bool good = true;
    while (good) {
      while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r' || *p == ',')) ++p;
      if (p == end) break;
      double v = 0;
      const auto [next, ec] = std::from_chars(p, end, v);
      good = ec == std::errc{} && std::isfinite(v) && count < command_.size();
      if (good) values[count++] = v;
      p = next;
    }
    length_ = 0;
    if (!good || count != command_.size()) {
      stats_[1] += 1;
      return Status::ok();
    }
    for (std::size_t i = 0; i < count; ++i) command_[i] = values[i];
    stats_[0] += 1;
    return Status::ok();
  }

  Status kill() override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    return Status::ok();
  }

 private:
  int fd_ = -1;
  std::int64_t cost_ns_ = 0;
  const CycleTiming* timing_ = nullptr;
  std::array<char, 4096> buffer_{};
  std::size_t length_ = 0;
  Out<double> command_;
  Out<double> stats_;
  Out<double> udp_port_;
};

CHIMERA_REGISTER_MODULE(UdpCommand);

}  // namespace
}  // namespace chimera::modules
