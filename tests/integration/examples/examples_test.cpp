// The example subsystem files: each passes `chimera verify` (exit 0), and the paper's examples
// run on the virtual clock and do what they promise. Figures 8 and 9 (examples/visual_servo.yaml):
// each configuration on its own servoes the arm onto the moving target, which takes the arm near
// the singular posture of the straight elbow and back; Figure 3 (examples/fig3_join.yaml): the
// joined x_d is less noisy than either camera's.

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"
#include "chimera/reconfig/switch_record.hpp"
#include "cli/run_chimera.hpp"
#include "kinematics/pose.hpp"
#include "visual_servo/target_path.hpp"

namespace chimera::test {
namespace {

constexpr std::int64_t kMs = 1'000'000;
const std::string kExamples = CHIMERA_EXAMPLES_DIR;

std::vector<std::string> example_files() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(kExamples))
    if (entry.path().extension() == ".yaml") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(Examples, EveryFilePassesChimeraVerify) {
  const auto files = example_files();
  ASSERT_GE(files.size(), 3U);
  TempDir dir;
  for (const auto& file : files) {
    const Outcome o = run_chimera(dir, "verify " + quoted(file));
    EXPECT_EQ(o.exit_code, 0) << file << ":\n" << o.out << o.err;
    EXPECT_NE(o.out.find("legal"), std::string::npos) << o.out;
  }
  // The two configurations of Figures 8 and 9 one by one, too.
  for (const char* config : {"standard", "near_singularity"}) {
    const Outcome o = run_chimera(dir, "verify " + quoted(kExamples + "/visual_servo.yaml") + " --config " + config);
    EXPECT_EQ(o.exit_code, 0) << config << ":\n" << o.out << o.err;
  }
}

SubsystemSpec load_example(const std::string& name) {
  auto spec = load_subsystem_file(kExamples + "/" + name, Registry::global());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  return spec.ok() ? std::move(spec).value() : SubsystemSpec{};
}

std::unique_ptr<Subsystem> start(const SubsystemSpec& spec, const std::string& config) {
  RunOptions options;
  options.clock = ClockKind::kVirtual;
  options.configuration = config;
  options.shm_suffix = "_examples_" + std::to_string(::getpid()) + "_" + config;
  auto sub = Subsystem::create(spec, Registry::global(), options);
  EXPECT_TRUE(sub.ok()) << (sub.ok() ? "" : sub.error().message);
  if (!sub.ok()) return nullptr;
  auto started = (*sub)->start();
  EXPECT_TRUE(started.ok()) << (started.ok() ? "" : started.error().message);
  return started.ok() ? std::move(sub).value() : nullptr;
}

std::vector<double> value_of(const Subsystem& sub, const std::string& variable) {
  auto v = sub.get(variable);
  EXPECT_TRUE(v.ok()) << variable;
  return v.ok() ? *v : std::vector<double>(64, 0.0);
}

// The target's path as the file's task `task` declares it (its params over the module's defaults).
modules::TargetPath path_of(const SubsystemSpec& spec, const std::string& task) {
  modules::TargetPathSettings s;
  for (const auto& t : spec.tasks) {
    if (t.name != task) continue;
    const auto fill = [&](const char* name, std::array<double, 6>& out) {
      const Vector v = t.params.vector(name);
      EXPECT_EQ(v.size(), 6U) << name;
      std::copy_n(v.begin(), std::min<std::size_t>(v.size(), 6), out.begin());
    };
    fill("center", s.center);
    fill("amplitude", s.amplitude);
    fill("frequency", s.frequency);
    fill("phase", s.phase);
  }
  return modules::TargetPath(s);
}

double position_distance(const std::vector<double>& x, const kinematics::Pose& target) {
  const kinematics::Pose pose = kinematics::pose_from(x);
  return (pose.position - target.position).norm();
}

double manipulability(const std::vector<double>& jacobian) {
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> j(jacobian.data());
  return std::fabs(j.determinant());
}

double norm(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x * x;
  return std::sqrt(s);
}

struct Tracking {
  double initial_error = 0.0;       // m, tool to target at start
  double worst_error = 0.0;         // m, after the first 2 s
  double worst_error_at = 0.0;      // s
  double rms_error = 0.0;           // m, after the first 2 s
  double lowest_w = 1.0;            // manipulability
  double lowest_w_at = 0.0;         // s
  double fastest_theta_d = 0.0;     // rad/s, |d theta_d / dt| over a period (joint vector norm), after 2 s
  double fastest_theta_d_at = 0.0;  // s
  double fastest_near = 0.0;        // rad/s, the same while the manipulability is below 0.045
  double straightest_elbow = 0.0;   // rad, the elbow's closest approach to pi/2 (its distance)
};

// The file, with its singularity monitor silenced unless `switching`: then the configuration
// given stays on, whatever the manipulability.
SubsystemSpec visual_servo(bool switching) {
  SubsystemSpec spec = load_example("visual_servo.yaml");
  if (!switching)
    for (auto& t : spec.tasks)
      if (t.module == "singularity_monitor") {
        t.params.set("enter", 1e-9);
        t.params.set("leave", 1e9);
      }
  return spec;
}

Tracking track(const std::string& config, std::int64_t duration_ns, bool switching = false,
               std::vector<SwitchRecord>* switches = nullptr) {
  Tracking out;
  const SubsystemSpec spec = visual_servo(switching);
  auto sub = start(spec, config);
  if (!sub) return out;
  const auto path = path_of(spec, "vision");
  out.initial_error = position_distance(value_of(*sub, "x_m"), path.at(0.0));
  out.straightest_elbow = 10.0;
  double sum_sq = 0.0;
  int samples = 0;
  auto previous = value_of(*sub, "theta_d");
  double last_w = 1.0;
  for (std::int64_t t = kMs; t <= duration_ns; t += kMs) {
    sub->run_for(kMs);
    const auto theta_d = value_of(*sub, "theta_d");
    for (std::size_t i = 0; i < previous.size(); ++i) previous[i] = (theta_d[i] - previous[i]) / 1e-3;
    if (last_w < 0.045) out.fastest_near = std::max(out.fastest_near, norm(previous));
    if (t > 2000 * kMs && norm(previous) > out.fastest_theta_d) {
      out.fastest_theta_d = norm(previous);
      out.fastest_theta_d_at = static_cast<double>(t) * 1e-9;
    }
    previous = theta_d;
    if (t % (10 * kMs) != 0) continue;
    const double seconds = static_cast<double>(t) * 1e-9;
    const double w = manipulability(value_of(*sub, "jacobian"));
    last_w = w;
    if (w < out.lowest_w) {
      out.lowest_w = w;
      out.lowest_w_at = seconds;
    }
    out.straightest_elbow = std::min(out.straightest_elbow, std::fabs(value_of(*sub, "theta_m")[2] - M_PI / 2));
    if (t <= 2000 * kMs) continue;
    const double e = position_distance(value_of(*sub, "x_m"), path.at(seconds));
    if (e > out.worst_error) {
      out.worst_error = e;
      out.worst_error_at = seconds;
    }
    sum_sq += e * e;
    ++samples;
  }
  out.rms_error = std::sqrt(sum_sq / samples);
  for (const auto& task : sub->snapshot()) {
    if (task.state != TaskState::kNotCreated && !switching) {
      EXPECT_EQ(task.state, TaskState::kOn) << task.name << ": " << task.last_error;
    }
    // The robot and the tasks both configurations share never lose a cycle, switches or not.
    if (task.name == "robot" || task.name == "fk") {
      EXPECT_EQ(task.stats.cycles, static_cast<std::uint64_t>(duration_ns / kMs)) << task.name;
    }
    EXPECT_NE(task.state, TaskState::kError) << task.name << ": " << task.last_error;
  }
  if (switches != nullptr) *switches = sub->switches();
  std::cout << config << ": tool to target " << out.initial_error * 1000 << " mm at start, then (after 2 s) worst "
            << out.worst_error * 1000 << " mm (at " << out.worst_error_at << " s), RMS " << out.rms_error * 1000
            << " mm; lowest manipulability " << out.lowest_w << " at " << out.lowest_w_at << " s, elbow within "
            << out.straightest_elbow << " rad of straight; fastest theta_d " << out.fastest_theta_d << " rad/s at "
            << out.fastest_theta_d_at << " s, " << out.fastest_near << " rad/s near the singularity\n";
  return out;
}

// Each configuration on its own, 20 s: two passes near the singular posture and back. The
// tool follows the target within the latency and the vision period of its motion (up to about
// 6 cm/s) and the camera's noise; worst near the singular posture.
TEST(Examples, BothConfigurationsOfFigures8And9TrackTheTargetNearTheSingularityAndBack) {
  const Tracking standard = track("standard", 20'000 * kMs);
  const Tracking damped = track("near_singularity", 20'000 * kMs);
  for (const Tracking* t : {&standard, &damped}) {
    EXPECT_LT(t->initial_error, 0.005);  // the robot starts at the target's first pose
    EXPECT_LT(t->worst_error, 0.015);
    EXPECT_LT(t->rms_error, 0.006);
    EXPECT_LT(t->lowest_w, 0.035);  // it did come near the singularity (from about 0.11)
    EXPECT_LT(t->straightest_elbow, 0.25);
  }
  // Why the paper switches: near the singular posture the exact inverse asks for joint speeds
  // that the damped one does not.
  EXPECT_LT(damped.fastest_theta_d, 3.0);
  EXPECT_GT(standard.fastest_theta_d, 10.0 * damped.fastest_theta_d);
}

// The paper's dynamic reconfiguration (3.4) in the same run: the monitor asks for damped least
// squares as the manipulability falls below 0.06 on the way to the straight elbow, and for the
// exact inverse again once it is above 0.075. The switches come in pairs around the two passes
// near the singular posture (at about 5 s and 15 s), the robot runs every cycle, and the joint
// speeds the exact inverse would ask for near the singularity are never asked.
TEST(Examples, Figures8And9SwitchNearTheSingularityAndBack) {
  std::vector<SwitchRecord> switches;
  const Tracking t = track("standard", 20'000 * kMs, /*switching=*/true, &switches);
  ASSERT_EQ(switches.size(), 4U);
  for (std::size_t i = 0; i < switches.size(); ++i) {
    EXPECT_EQ(switches[i].cause, "requested by monitor");
    EXPECT_EQ(switches[i].to, i % 2 == 0 ? "near_singularity" : "standard");
    std::cout << describe(switches[i]) << "\n";
  }
  EXPECT_TRUE(switches[0].flag_raised) << "the first creates dls and integ";
  EXPECT_FALSE(switches[2].flag_raised) << "the second pass finds them created";
  const double first_in = static_cast<double>(switches[0].committed_ns) * 1e-9;
  const double second_in = static_cast<double>(switches[2].committed_ns) * 1e-9;
  EXPECT_GT(first_in, 2.0);
  EXPECT_LT(first_in, 5.0);
  EXPECT_GT(second_in, 12.0);
  EXPECT_LT(second_in, 15.0);
  EXPECT_LT(t.worst_error, 0.015);
  EXPECT_LT(t.rms_error, 0.006);
  // Near the singular posture (w < 0.045) the exact inverse alone asks for tens of rad/s; with the
  // switches, damped least squares has taken over by then. (Away from it the exact inverse steps
  // theta_d with each 30 ms frame of the camera: fast for a millisecond, and the robot's servo
  // limits it; that is no singularity.)
  EXPECT_LT(t.fastest_near, 3.0) << "damped least squares took over before the exact inverse ran away";
  const Tracking alone = track("standard", 20'000 * kMs);
  EXPECT_GT(alone.fastest_near, 10.0 * t.fastest_near);
}

TEST(Examples, Figure3JoinsTwoCamerasIntoALessNoisyPose) {
  const SubsystemSpec spec = load_example("fig3_join.yaml");
  auto sub = start(spec, "joined");
  ASSERT_NE(sub, nullptr);
  const auto path = path_of(spec, "camera_a");  // both cameras watch the default path
  const auto latency = spec.tasks[0].params.number("latency");
  std::array<double, 3> sum_sq{};
  int samples = 0;
  sub->run_for(100 * kMs);
  for (int k = 0; k < 1000; ++k) {
    sub->run_for(30 * kMs);
    const double released = 0.030 * (4 + k);
    const auto target = path.at(released - latency);
    const std::array<std::string, 3> names{"x_d_a", "x_d_b", "x_d"};
    for (std::size_t i = 0; i < 3; ++i) {
      const double e = position_distance(value_of(*sub, names[i]), target);
      sum_sq[i] += e * e / 3.0;
    }
    ++samples;
  }
  std::array<double, 3> sigma{};
  for (std::size_t i = 0; i < 3; ++i) sigma[i] = std::sqrt(sum_sq[i] / samples);
  std::cout << "Figure 3: error per axis of camera a " << sigma[0] * 1000 << " mm, camera b " << sigma[1] * 1000
            << " mm, joined " << sigma[2] * 1000 << " mm (inverse-variance weights: expected "
            << 1000 / std::sqrt(1.0 / 1e-6 + 1.0 / 2.25e-6) << " mm)\n";
  EXPECT_NEAR(sigma[0], 0.001, 0.0001);
  EXPECT_NEAR(sigma[1], 0.0015, 0.00015);
  EXPECT_NEAR(sigma[2], 1.0 / std::sqrt(1.0 / 1e-6 + 1.0 / 2.25e-6), 0.0001);
  EXPECT_LT(sigma[2], sigma[0]);
  // And the arm follows the joined pose.
  EXPECT_LT(position_distance(value_of(*sub, "x_m"), kinematics::pose_from(value_of(*sub, "x_d"))), 0.01);
}

}  // namespace
}  // namespace chimera::test
