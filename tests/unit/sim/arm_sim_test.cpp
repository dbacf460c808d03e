// The simulated arm behind the robot interfaces: loading, physics, time keeping, limits,
// determinism, and no allocation on the real-time calls.

#include "chimera/sim/arm_sim.hpp"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/allocation_guard.hpp"

namespace chimera::sim {
namespace {

std::unique_ptr<ArmSim> load_arm(SensorNoise noise = {}) {
  auto r = ArmSim::load("", noise);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? std::move(r).value() : nullptr;
}

constexpr std::int64_t kMs = 1'000'000;

// A scratch folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() / ("chimera_sim_test_" + std::to_string(::getpid()) + "_" +
                                                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] std::string write(const std::string& name, const std::string& text) const {
    const auto file = path_ / name;
    std::ofstream(file) << text;
    return file.string();
  }
  [[nodiscard]] std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

constexpr const char* kTwoJointModel = R"(<mujoco model="two">
  <worldbody><body><joint name="a" type="hinge" axis="0 0 1"/><geom size="0.1" mass="1"/>
    <body pos="0.3 0 0"><joint name="b" type="hinge" axis="0 0 1"/><geom size="0.1" mass="1"/></body>
  </body></worldbody>
  <actuator><motor joint="a" ctrllimited="true" ctrlrange="-1 1"/><motor joint="b"/></actuator>
</mujoco>)";

TEST(ArmSim, LoadsTheShippedSixJointArm) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  EXPECT_EQ(arm->ndof(), 6);
  EXPECT_EQ(arm->timestep_ns(), kMs);
  EXPECT_EQ(std::filesystem::path(arm->path()).filename(), "arm6.xml");
  EXPECT_EQ(arm->positions().size(), 6U);
  EXPECT_EQ(arm->velocities().size(), 6U);
  EXPECT_EQ(arm->time_ns(), 0);
  EXPECT_DOUBLE_EQ(arm->torque_max(0), 150.0);
  EXPECT_DOUBLE_EQ(arm->torque_min(2), -80.0);
  EXPECT_DOUBLE_EQ(arm->torque_max(5), 20.0);
}

TEST(ArmSim, FallsUnderGravityWithZeroTorque) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  for (int k = 0; k < 500; ++k) arm->step(kMs);
  // The upper arm sticks out horizontally at zero: with nothing holding it, the shoulder drops.
  EXPECT_LT(arm->positions()[1], -0.1);
  EXPECT_GT(std::fabs(arm->velocities()[1]), 0.1);
  EXPECT_FALSE(arm->diverged());
}

TEST(ArmSim, StaysPutWithoutGravity) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  arm->set_gravity({0.0, 0.0, 0.0});
  for (int k = 0; k < 1000; ++k) arm->step(kMs);
  for (double q : arm->positions()) EXPECT_NEAR(q, 0.0, 1e-12);
  for (double qd : arm->velocities()) EXPECT_NEAR(qd, 0.0, 1e-12);
}

TEST(ArmSim, OneSecondInMillisecondStepsIsExactlyOneSecond) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  for (int k = 0; k < 1000; ++k) arm->step(kMs);
  EXPECT_EQ(arm->time_ns(), 1'000'000'000);
  EXPECT_EQ(arm->time_s(), 1.0);
}

TEST(ArmSim, CarriesTheRemainderOfStepsShorterThanATimestep) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  arm->step(999'999);  // under one MuJoCo step: nothing happens yet...
  EXPECT_EQ(arm->time_ns(), 0);
  arm->step(1);  // ...until the remainder adds up
  EXPECT_EQ(arm->time_ns(), kMs);
  // 1.5 ms at a time for 1000 calls: 1.5 s, not 1 s or 2 s.
  for (int k = 0; k < 1000; ++k) arm->step(1'500'000);
  EXPECT_EQ(arm->time_ns(), kMs + 1'500'000'000);
  // 300 us at a time, 10'000 calls: exactly 3 s more, whatever the order of the carries.
  for (int k = 0; k < 10'000; ++k) arm->step(300'000);
  EXPECT_EQ(arm->time_ns(), kMs + 1'500'000'000 + 3'000'000'000);
  arm->step(0);
  arm->step(-5);
  EXPECT_EQ(arm->time_ns(), kMs + 4'500'000'000);
}

TEST(ArmSim, ClampsTorqueToTheActuatorRange) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  const std::vector<double> huge{1e6, -1e6, 1e6, -1e6, 1e6, std::nan("")};
  arm->set_torque(huge);
  const std::vector<double> expected{150, -150, 80, -20, 20, 0};
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_DOUBLE_EQ(arm->torque()[i], expected[i]) << "joint " << i;

  // The clamped command moves the arm exactly as the limit itself does.
  auto limited = load_arm();
  ASSERT_NE(limited, nullptr);
  limited->set_torque(expected);
  for (int k = 0; k < 200; ++k) {
    arm->step(kMs);
    limited->step(kMs);
  }
  for (int i = 0; i < 6; ++i) EXPECT_EQ(arm->positions()[i], limited->positions()[i]);

  // Short input: the missing joints get zero.
  arm->set_torque(std::vector<double>{5.0});
  EXPECT_DOUBLE_EQ(arm->torque()[0], 5.0);
  EXPECT_DOUBLE_EQ(arm->torque()[1], 0.0);
}

// A torque profile that exercises every joint, with noisy measurements.
std::vector<double> run_profile(ArmSim& arm, int steps) {
  std::vector<double> trace;
  std::vector<double> tau(6);
  for (int k = 0; k < steps; ++k) {
    for (std::size_t i = 0; i < tau.size(); ++i) tau[i] = 10.0 * std::sin(0.01 * k + static_cast<double>(i));
    arm.set_torque(tau);
    arm.step(kMs);
    trace.insert(trace.end(), arm.positions().begin(), arm.positions().end());
    trace.insert(trace.end(), arm.velocities().begin(), arm.velocities().end());
  }
  return trace;
}

TEST(ArmSim, IdenticalRunsGiveIdenticalStates) {
  const SensorNoise noise{0.001, 0.01, 42};
  auto a = load_arm(noise);
  auto b = load_arm(noise);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  const auto ta = run_profile(*a, 1000);
  const auto tb = run_profile(*b, 1000);
  ASSERT_EQ(ta.size(), tb.size());
  for (std::size_t i = 0; i < ta.size(); ++i) ASSERT_EQ(ta[i], tb[i]) << "sample " << i;  // bit for bit
  // After reset the same run repeats too.
  a->reset();
  EXPECT_EQ(run_profile(*a, 1000), ta);
}

TEST(ArmSim, NoiseIsInTheMeasurementOnly) {
  auto clean = load_arm();
  auto noisy = load_arm(SensorNoise{0.01, 0.0, 7});
  ASSERT_NE(clean, nullptr);
  ASSERT_NE(noisy, nullptr);
  double sum_sq = 0.0;
  int count = 0;
  for (int k = 0; k < 2000; ++k) {
    clean->step(kMs);
    noisy->step(kMs);
    for (int i = 0; i < 6; ++i) {
      const double d = noisy->positions()[i] - clean->positions()[i];
      sum_sq += d * d;
      ++count;
      // Velocity noise is off, and the dynamics never see the noise.
      ASSERT_EQ(noisy->velocities()[i], clean->velocities()[i]);
    }
  }
  EXPECT_NEAR(std::sqrt(sum_sq / count), 0.01, 0.001);
}

TEST(ArmSim, SetStatePutsTheArmThere) {
  auto arm = load_arm();
  ASSERT_NE(arm, nullptr);
  const std::vector<double> q{0.1, 0.2, -0.3, 0.4, -0.5, 0.6};
  const std::vector<double> qd{1, 0, 0, 0, 0, -1};
  arm->set_state(q, qd);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(arm->positions()[i], q[i]);
    EXPECT_EQ(arm->velocities()[i], qd[i]);
  }
  EXPECT_EQ(arm->time_ns(), 0);
}

#if CHIMERA_ALLOCATION_GUARD  // plain builds: a sanitizer brings its own allocator
TEST(ArmSim, RealTimeCallsDoNotAllocate) {
  auto arm = load_arm(SensorNoise{0.001, 0.001, 3});
  ASSERT_NE(arm, nullptr);
  const std::vector<double> tau{1, 2, 3, 0.1, 0.2, 0.3};
  const std::vector<double> q(6, 0.1);
  long allocations = 0;
  {
    testing::AllocationGuard guard;
    for (int k = 0; k < 100; ++k) {
      arm->set_torque(tau);
      arm->step(k % 3 == 0 ? 2'500'000 : kMs);
      volatile double sink = arm->positions()[0] + arm->velocities()[0] + arm->torque()[0] + arm->time_s();
      (void)sink;
    }
    arm->set_state(q, q);
    allocations = testing::AllocationGuard::count();
  }
  EXPECT_EQ(allocations, 0);
}
#endif

TEST(ArmSim, AMissingModelNamesThePath) {
  auto r = ArmSim::load("/nonexistent/chimera/arm.xml");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("/nonexistent/chimera/arm.xml"), std::string::npos) << r.error().message;
}

TEST(ArmSim, ABrokenModelGivesMuJoCosMessageAndThePath) {
  TempDir dir;
  const auto file = dir.write("broken.xml", "<mujoco><worldbody><geom size='oops'/></worldbody></mujoco>");
  auto r = ArmSim::load(file);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(file), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("size"), std::string::npos) << r.error().message;
}

TEST(ArmSim, RefusesAModelThatIsNotOneMotorPerJoint) {
  TempDir dir;
  const auto file = dir.write("free.xml", R"(<mujoco><worldbody><body><freejoint/><geom size="0.1"/></body>
    </worldbody></mujoco>)");
  auto r = ArmSim::load(file);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("actuator"), std::string::npos) << r.error().message;
}

TEST(ArmSim, FindsModelsOnChimeraModelPath) {
  TempDir dir;
  (void)dir.write("arm6.xml", kTwoJointModel);
  // The environment is only touched while this single-threaded test runs.
  const char* old = std::getenv("CHIMERA_MODEL_PATH");  // NOLINT(concurrency-mt-unsafe)
  const std::string saved = old != nullptr ? old : "";
  ::setenv("CHIMERA_MODEL_PATH", ("/nonexistent:" + dir.str()).c_str(), 1);  // NOLINT(concurrency-mt-unsafe)
  auto r = ArmSim::load("");  // the default name, found first on the override path
  if (old != nullptr) {
    ::setenv("CHIMERA_MODEL_PATH", saved.c_str(), 1);  // NOLINT(concurrency-mt-unsafe)
  } else {
    ::unsetenv("CHIMERA_MODEL_PATH");  // NOLINT(concurrency-mt-unsafe)
  }
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ((*r)->ndof(), 2);
  // An unlimited actuator has no clamp.
  EXPECT_DOUBLE_EQ((*r)->torque_max(0), 1.0);
  EXPECT_GT((*r)->torque_max(1), 1e9);
}

}  // namespace
}  // namespace chimera::sim
