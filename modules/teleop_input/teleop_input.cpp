// teleop_input: the teleoperation input of the paper's Figure 6. Its resource port takes an
// operator's commands (teleop_command.hpp) from UDP datagrams, sent by scripts/chimera-teleop
// from its command line, the keyboard or a recording, or replays a recorded session on the
// subsystem's clock; it turns them into the goal pose x_goal that cartesian_interp follows.

#include "module_docs/teleop_input.hpp"

#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "cartesian_interp/cartesian_motion.hpp"
#include "chimera/module/registry.hpp"
#include "support/module_support.hpp"
#include "support/udp_socket.hpp"
#include "teleop_command.hpp"

namespace chimera::modules {
namespace {

using cartesian::finite_pose;
using cartesian::Pose;
using cartesian::Vec3;
using kinematics::pose_from;
using teleop::Command;
using teleop::Verb;

constexpr std::size_t kMaxDatagramsPerCycle = 32;
constexpr std::size_t kDatagramBytes = 512;

// One command of a recorded session: when (s after the task was turned on) and what.
struct TimedCommand {
  std::int64_t at_ns = 0;
  Command command;
};

// "1.5 move 0.05 0 0": seconds, then a command. Comments (#) and blank lines are skipped by the
// caller. False for anything else.
bool parse_timed(std::string_view line, TimedCommand& out) {
  while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
  double seconds = 0.0;
  const auto [end, ec] = std::from_chars(line.data(), line.data() + line.size(), seconds);
  if (ec != std::errc() || !(seconds >= 0.0) || !std::isfinite(seconds)) return false;
  out.at_ns = std::llround(seconds * 1e9);
  return teleop::parse_command(line.substr(static_cast<std::size_t>(end - line.data())), out.command);
}

bool skipped(std::string_view line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first == std::string_view::npos || line[first] == '#';
}

class TeleopInput final : public Module {
 public:
  static constexpr const char* kName = "teleop_input";
  static constexpr const char* kSummary = docs::teleop_input::kSummary;
  static constexpr const char* kDoc = docs::teleop_input::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_var("x_m", Dim::fixed(6), "measured tool pose [x y z rx ry rz], m and rad");
    d.out_var("x_goal", Dim::fixed(6), "goal tool pose, m and rad (NaN until x_m is known)");
    d.out_var("teleop_stats", Dim::fixed(3), "[commands accepted, commands refused, UDP port bound]");
    d.param("source", std::string("udp"), "", "udp (datagrams on address:port) or replay (session or record)")
        .one_of({"udp", "replay"});
    d.param("address", std::string("127.0.0.1"), "", "IPv4 address to bind (udp)");
    d.param("port", 0.0, "", "UDP port to bind; 0: the system chooses (teleop_stats[2] says which)")
        .whole()
        .at_least(0)
        .at_most(65535);
    d.param("session", StringList{}, "", "recorded commands, `seconds command` each (replay)");
    d.param("record", std::string(), "", "a file of recorded commands, one `seconds command` a line (replay)");
    d.param("timeout", 0.5, "s", "a vel motion stops after this long without a command").greater_than(0);
    d.param("max_distance", 0.5, "m", "the goal's position stays this close to where it started (0: no limit)")
        .at_least(0);
    d.resource("UDP datagrams of operator commands, or a recorded session replayed on the subsystem's clock");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    timeout_ns_ = std::llround(p.number("timeout", 0.5) * 1e9);
    max_distance_ = p.number("max_distance", 0.5);
    if (!(timeout_ns_ > 0) || !(max_distance_ >= 0.0))
      return Status::fail("teleop_input: timeout must be > 0 s and max_distance >= 0 m");
    dt_ = ctx.period_s();
    if (dt_ <= 0.0) return Status::fail("teleop_input: the task must be periodic (give it a period)");
    x_m_ = ctx.in<double>("x_m");
    x_goal_ = ctx.out<double>("x_goal");
    stats_ = ctx.out<double>("teleop_stats");
    if (ctx.failed()) return Status::ok();  // InitContext names the port that did not bind
    timing_ = &ctx.timing();
    for (double& v : x_goal_.values()) v = std::numeric_limits<double>::quiet_NaN();

    const std::string source = p.text("source", "udp");
    if (source == "udp") return open_socket(p);
    if (source == "replay") return load_session(p);
    return Status::fail("teleop_input: source must be udp or replay");
  }

  Status on() override {
    on_ns_ = timing_->release_ns;
    next_ = 0;
    started_ = false;
    moving_ = false;
    for (double& v : x_goal_.values()) v = std::numeric_limits<double>::quiet_NaN();
    return Status::ok();
  }

  Status cycle() override {
    const std::int64_t now = timing_->release_ns;
    if (!started_ && x_m_.has_data() && finite_pose(x_m_.values())) {
      origin_ = goal_ = pose_from(x_m_.values());
      started_ = true;
    }
    if (fd_ >= 0) receive(now);
    while (next_ < session_.size() && session_[next_].at_ns <= now - on_ns_) apply(session_[next_++].command, now);
    if (moving_ && now - last_command_ns_ > timeout_ns_) moving_ = false;  // the dead man's switch
    if (moving_) goal_ = cartesian::displaced(goal_, velocity_ * dt_, angular_velocity_ * dt_);
    if (started_) {
      keep_within_reach();
      kinematics::write_pose(goal_, x_goal_.values());
    }
    stats_[0] = static_cast<double>(accepted_);
    stats_[1] = static_cast<double>(refused_);
    stats_[2] = static_cast<double>(port_);
    return Status::ok();
  }

  Status kill() override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    return Status::ok();
  }

 private:
  Status open_socket(const Params& p) {
    const UdpSocket socket = bind_udp(p.text("address", "127.0.0.1"), p.number("port", 0.0));
    if (socket.fd < 0) return Status::fail(socket.error);
    fd_ = socket.fd;
    port_ = socket.port;
    return Status::ok();
  }

  Status load_session(const Params& p) {
    std::vector<std::string> lines = p.strings("session");
    if (const std::string file = p.text("record"); !file.empty()) {
      std::ifstream in(file);
      if (!in) return Status::fail(intern("teleop_input: cannot read the record file " + file));
      for (std::string line; std::getline(in, line);) lines.push_back(line);
    }
    for (const auto& line : lines) {
      if (skipped(line)) continue;
      TimedCommand c;
      if (!parse_timed(line, c))
        return Status::fail(intern("teleop_input: \"" + line + "\" is not `seconds command` (e.g. 1.5 move 0.05 0 0)"));
      if (!session_.empty() && c.at_ns < session_.back().at_ns)
        return Status::fail("teleop_input: the recorded commands must be in time order");
      session_.push_back(c);
    }
    if (session_.empty()) return Status::fail("teleop_input: source replay needs session or record");
    return Status::ok();
  }

  // Every datagram waiting, up to a bound, each one or more lines of commands. Non-blocking.
  void receive(std::int64_t now) noexcept {
    for (std::size_t n = 0; n < kMaxDatagramsPerCycle; ++n) {
      const ssize_t got = ::recv(fd_, buffer_.data(), buffer_.size(), MSG_DONTWAIT);
      if (got <= 0) return;
      const std::string_view text(buffer_.data(), static_cast<std::size_t>(got));
      std::size_t start = 0;
      while (start < text.size()) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        const std::string_view line = text.substr(start, end - start);
        if (!skipped(line)) {
          Command c;
          if (teleop::parse_command(line, c))
            apply(c, now);
          else
            ++refused_;
        }
        start = end + 1;
      }
    }
  }

  void apply(const Command& c, std::int64_t now) noexcept {
    if (!started_) {  // where the tool is is not known yet: a step from where?
      ++refused_;
      return;
    }
    const auto& v = c.values;
    const Vec3 linear(v[0], v[1], v[2]);
    const Vec3 angular(v[3], v[4], v[5]);
    moving_ = false;
    switch (c.verb) {
      case Verb::kMove: goal_ = cartesian::displaced(goal_, linear, angular); break;
      case Verb::kGoto: goal_ = pose_from(v); break;
      case Verb::kVel:
        velocity_ = linear;
        angular_velocity_ = angular;
        moving_ = true;
        break;
      case Verb::kStop: break;
      case Verb::kHold:
        if (x_m_.has_data() && finite_pose(x_m_.values())) goal_ = pose_from(x_m_.values());
        break;
      case Verb::kHome: goal_ = origin_; break;
    }
    last_command_ns_ = now;
    ++accepted_;
  }

  void keep_within_reach() noexcept {
    if (max_distance_ <= 0.0) return;
    const Vec3 away = goal_.position - origin_.position;
    if (away.norm() > max_distance_) goal_.position = origin_.position + away * (max_distance_ / away.norm());
  }

  // Parameters and ports.
  std::int64_t timeout_ns_ = 0;
  double max_distance_ = 0.0;
  double dt_ = 0.0;
  In<double> x_m_;
  Out<double> x_goal_;
  Out<double> stats_;
  const CycleTiming* timing_ = nullptr;

  // The resource port.
  int fd_ = -1;
  int port_ = 0;
  std::array<char, kDatagramBytes> buffer_{};
  std::vector<TimedCommand> session_;
  std::size_t next_ = 0;

  // The goal.
  bool started_ = false;
  Pose origin_;
  Pose goal_;
  bool moving_ = false;
  Vec3 velocity_ = Vec3::Zero();
  Vec3 angular_velocity_ = Vec3::Zero();
  std::int64_t on_ns_ = 0;
  std::int64_t last_command_ns_ = 0;
  std::uint64_t accepted_ = 0;
  std::uint64_t refused_ = 0;
};

}  // namespace

CHIMERA_REGISTER_MODULE(TeleopInput);

}  // namespace chimera::modules
