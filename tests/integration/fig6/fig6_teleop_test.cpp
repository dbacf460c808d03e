// The paper's Figure 6, Cartesian teleoperation (examples/fig6_teleop.yaml), on the virtual
// clock: the shipped recorded session moves the simulated arm's tool where each command says,
// by inverse kinematics and by resolved rate; the operator's UDP datagrams do the same.

#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cartesian_interp/cartesian_motion.hpp"
#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"
#include "support/probe_module.hpp"
#include "support/udp_sender.hpp"

namespace chimera {
namespace {

using kinematics::pose_from;
using kinematics::rotation_from_vector;
using modules::cartesian::rotation_error;
using modules::cartesian::Vec3;

constexpr std::int64_t kMs = 1'000'000;
const std::string kExample = CHIMERA_EXAMPLES_DIR "/fig6_teleop.yaml";

// The example's text with `from` replaced by `to` (each once), so that a test can bind port 0.
std::string example(const std::string& from = {}, const std::string& to = {}) {
  std::ifstream in(kExample);
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  if (!from.empty()) text.replace(text.find(from), from.size(), to);
  return text;
}

class Fig6Test : public ::testing::Test {
 protected:
  std::unique_ptr<Subsystem> start(const std::string& configuration, const std::string& text = example()) {
    auto spec = load_subsystem_text(text, "fig6_teleop.yaml", Registry::global());
    if (!spec) {
      ADD_FAILURE() << spec.error().message;
      return nullptr;
    }
    spec_ = std::make_unique<SubsystemSpec>(*std::move(spec));
    RunOptions o;
    o.clock = ClockKind::kVirtual;
    o.configuration = configuration;
    o.shm_suffix = testing::unique_suffix();
    // The logger writes below CHIMERA_LOG_DIR: a directory of this process's own.
    std::filesystem::create_directories(log_dir_);
    ::setenv("CHIMERA_LOG_DIR", log_dir_.c_str(), 1);  // NOLINT(concurrency-mt-unsafe): one thread
    auto s = Subsystem::create(*spec_, Registry::global(), o);
    if (!s) {
      ADD_FAILURE() << s.error().message;
      return nullptr;
    }
    if (auto started = (*s)->start(); !started) {
      ADD_FAILURE() << started.error().message;
      return nullptr;
    }
    return std::move(*s);
  }

  static std::vector<double> get(const Subsystem& s, const std::string& variable) {
    auto v = s.get(variable);
    EXPECT_TRUE(v.ok()) << variable;
    return v.ok() && v->size() == 6 ? *v : std::vector<double>(6, 0.0);
  }

  // Runs until `t_ms` on the subsystem's clock.
  static void run_until(Subsystem& s, std::int64_t t_ms) {
    const std::int64_t left = t_ms * kMs - s.now_ns();
    if (left > 0) s.run_for(left);
  }

  // The tool's position is `offset` from `start`, within `tolerance` (m).
  static void expect_at(const std::vector<double>& x, const std::vector<double>& start, const Vec3& offset,
                        double tolerance, const std::string& when) {
    const Vec3 p(x[0], x[1], x[2]);
    const Vec3 expected = Vec3(start[0], start[1], start[2]) + offset;
    EXPECT_LT((p - expected).norm(), tolerance)
        << when << ": at " << p.transpose() << ", expected " << expected.transpose();
  }

  // The angle between two poses' orientations, rad.
  static double turn_between(const std::vector<double>& a, const std::vector<double>& b) {
    return rotation_error(pose_from(a).rotation, pose_from(b).rotation).norm();
  }

  // The recorded session of the example, checked step by step on the measured pose.
  void follows_the_session(const std::string& configuration, double tolerance) {
    auto s = start(configuration);
    ASSERT_NE(s, nullptr);
    run_until(*s, 10);
    const auto home = get(*s, "x_m");
    run_until(*s, 990);
    expect_at(get(*s, "x_m"), home, Vec3::Zero(), 1e-4, "before the first command the tool holds still");

    // 5 cm forward, on a straight line: y and z stay put while x moves.
    for (std::int64_t t = 1000; t <= 1900; t += 100) {
      run_until(*s, t);
      const auto x = get(*s, "x_m");
      EXPECT_NEAR(x[1], home[1], tolerance) << "t = " << t << " ms";
      EXPECT_NEAR(x[2], home[2], tolerance) << "t = " << t << " ms";
    }
    expect_at(get(*s, "x_m"), home, Vec3(0.05, 0, 0), tolerance, "after move 0.05 0 0");
    run_until(*s, 2900);
    expect_at(get(*s, "x_m"), home, Vec3(0.05, 0.05, 0), tolerance, "after move 0 0.05 0");
    run_until(*s, 3900);
    expect_at(get(*s, "x_m"), home, Vec3(0.05, 0.05, -0.05), tolerance, "after move 0 0 -0.05");
    run_until(*s, 4900);
    const auto turned = get(*s, "x_m");
    expect_at(turned, home, Vec3(0.05, 0.05, -0.05), tolerance, "a turn does not move the tool point");
    const Eigen::Matrix3d expected = rotation_from_vector(Vec3(0, 0, 0.3)) * pose_from(home).rotation;
    EXPECT_LT(rotation_error(expected, pose_from(turned).rotation).norm(), 20 * tolerance)
        << "turned 0.3 rad about the vertical (" << turn_between(turned, home) << " rad from the start)";
    // vel 0 -0.04 0 from 5 s, for the 0.5 s of the dead man's switch (51 cycles of 10 ms): 2.04 cm.
    run_until(*s, 6900);
    expect_at(get(*s, "x_m"), home, Vec3(0.05, 0.05 - 0.0204, -0.05), tolerance, "after vel and its timeout");
    run_until(*s, 9000);
    expect_at(get(*s, "x_m"), home, Vec3::Zero(), tolerance, "home");
    EXPECT_LT(turn_between(get(*s, "x_m"), home), 20 * tolerance) << "home turns back too";
    EXPECT_EQ(s->get("teleop_stats")->at(0), 6.0) << "every recorded command carried out";
    for (const auto& t : s->snapshot()) EXPECT_NE(t.state, TaskState::kError) << t.name;
  }

  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(log_dir_, ignored);
  }

  std::unique_ptr<SubsystemSpec> spec_;
  std::filesystem::path log_dir_ =
      std::filesystem::temp_directory_path() / ("chimera_fig6_" + std::to_string(::getpid()));
};

TEST_F(Fig6Test, TheExampleVerifies) {
  auto spec = load_subsystem_file(kExample, Registry::global());
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  const auto violations = verify_subsystem(resolve_subsystem(*spec, Registry::global()), std::nullopt);
  for (const auto& v : violations) ADD_FAILURE() << v.message;
  EXPECT_EQ(spec->configurations.size(), 3u);
}

TEST_F(Fig6Test, ARecordedSessionByInverseKinematics) { follows_the_session("replay", 2e-4); }

TEST_F(Fig6Test, ARecordedSessionByResolvedRate) { follows_the_session("rate", 5e-4); }

TEST_F(Fig6Test, TheOperatorsDatagrams) {
  auto s = start("teleop", example("port: 47010", "port: 0"));
  ASSERT_NE(s, nullptr);
  run_until(*s, 100);
  const auto home = get(*s, "x_m");
  const auto stats = s->get("teleop_stats");
  ASSERT_TRUE(stats.ok());
  const testing::UdpSender operator_console(static_cast<int>((*stats)[2]));
  ASSERT_TRUE(operator_console.send("move 0 0 0.03"));
  ASSERT_TRUE(operator_console.send("move -0.02 0 0"));
  run_until(*s, 1500);
  expect_at(get(*s, "x_m"), home, Vec3(-0.02, 0, 0.03), 2e-4, "after two datagrams");
}

}  // namespace
}  // namespace chimera
