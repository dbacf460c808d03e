// The real-time path allocates nothing. While an AllocationGuard is armed every allocation is
// counted and operator new fails by throwing. Cycles of the framework (transfers, statistics,
// timing, dispatch) and of the library's modules run armed: Figure 4 on both clocks, Figures 8
// and 9 (the kinematics, the damped least squares, the integrator, the camera, the
// position-mode robot), Figure 3's join, and both robot interfaces' hold while the
// illegal-configuration flag is raised.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/exec/subsystem.hpp"
#include "support/allocation_guard.hpp"
#include "support/probe_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

using testing::AllocationGuard;

std::unique_ptr<Subsystem> fig4(ClockKind clock) {
  auto spec = load_subsystem_file(CHIMERA_EXAMPLES_DIR "/fig4_pid_joint.yaml", Registry::global());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  RunOptions o;
  o.clock = clock;
  o.shm_suffix = testing::unique_suffix();
  o.realtime_priorities = false;
  auto s = Subsystem::create(*spec, Registry::global(), o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  EXPECT_TRUE((*s)->start().ok());
  return std::move(*s);
}

std::uint64_t total_cycles(const Subsystem& s) {
  std::uint64_t n = 0;
  for (const auto& t : s.snapshot()) n += t.stats.cycles;
  return n;
}

TEST(NoAllocationInCycle, Figure4OnTheVirtualClock) {
  auto s = fig4(ClockKind::kVirtual);
  s->run_for(100 * kMs);  // warm up: first touches, lazy initialisation
  const auto before = total_cycles(*s);
  long allocations = 0;
  {
    AllocationGuard guard(AllocationGuard::OnNew::kFail);
    s->run_for(2000 * kMs);
    allocations = AllocationGuard::count();
  }
  EXPECT_EQ(allocations, 0) << "allocations inside cycles";
  EXPECT_EQ(total_cycles(*s) - before, s->snapshot().size() * 2000u);
  for (const auto& t : s->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name;
}

TEST(NoAllocationInCycle, Figure4OnTheRealClock) {
  auto s = fig4(ClockKind::kReal);
  s->run_for(100 * kMs);
  const auto before = total_cycles(*s);
  long allocations = 0;
  {
    AllocationGuard guard(AllocationGuard::OnNew::kFail);
    s->run_for(300 * kMs);  // every thread is counted, this one sleeps
    allocations = AllocationGuard::count();
  }
  EXPECT_EQ(allocations, 0) << "allocations inside cycles";
  EXPECT_GT(total_cycles(*s), before + 300);
  for (const auto& t : s->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name;
}

TEST(NoAllocationInCycle, Figure4WithSensorNoise) {
  const char* text = R"(subsystem: fig4_noise
tasks:
  - { name: traj, module: joint_traj_gen, period: 1ms }
  - { name: pid, module: pid_joint, period: 1ms }
  - { name: robot, module: robot_torque, period: 1ms, params: { noise_std: 0.001 } }
)";
  auto spec = load_subsystem_text(text, "fig4_noise.yaml", Registry::global());
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  RunOptions o;
  o.clock = ClockKind::kVirtual;
  o.shm_suffix = testing::unique_suffix();
  auto s = Subsystem::create(*spec, Registry::global(), o);
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_TRUE((*s)->start().ok());
  (*s)->run_for(10 * kMs);
  long allocations = 0;
  {
    AllocationGuard guard(AllocationGuard::OnNew::kFail);
    (*s)->run_for(500 * kMs);
    allocations = AllocationGuard::count();
  }
  EXPECT_EQ(allocations, 0) << "allocations during 500 cycles of each task";
  EXPECT_EQ(total_cycles(**s), 3u * 510u);
}

std::unique_ptr<Subsystem> example(const char* file, const char* config) {
  auto spec = load_subsystem_file(std::string(CHIMERA_EXAMPLES_DIR "/") + file, Registry::global());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  if (!spec.ok()) return nullptr;
  // A switch is prepared off the real-time path and may allocate (STYLE: prepare, then commit);
  // here the singularity monitor still computes every cycle but its thresholds never ask.
  for (auto& t : spec->tasks)
    if (t.module == "singularity_monitor") {
      t.params.set("enter", 1e-9);
      t.params.set("leave", 1e9);
    }
  RunOptions o;
  o.clock = ClockKind::kVirtual;
  o.configuration = config;
  o.shm_suffix = testing::unique_suffix();
  auto s = Subsystem::create(*spec, Registry::global(), o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  if (!s.ok()) return nullptr;
  EXPECT_TRUE((*s)->start().ok());
  return std::move(*s);
}

// Runs `s` armed for `ns` after a warm-up; every task ON must stay ON.
void expect_no_allocation(Subsystem& s, std::int64_t ns) {
  s.run_for(100 * kMs);
  long allocations = 0;
  {
    AllocationGuard guard(AllocationGuard::OnNew::kFail);
    s.run_for(ns);
    allocations = AllocationGuard::count();
  }
  EXPECT_EQ(allocations, 0) << "allocations inside cycles";
  for (const auto& t : s.snapshot()) {
    if (t.state != TaskState::kNotCreated) {
      EXPECT_EQ(t.state, TaskState::kOn) << t.name << ": " << t.last_error;
    }
  }
}

TEST(NoAllocationInCycle, Figure8InverseKinematicsOnThePositionModeRobot) {
  auto s = example("visual_servo.yaml", "standard");
  ASSERT_NE(s, nullptr);
  expect_no_allocation(*s, 6000 * kMs);  // through the pass near the singular posture at 5 s
}

TEST(NoAllocationInCycle, Figure9DampedLeastSquaresAndTheIntegrator) {
  auto s = example("visual_servo.yaml", "near_singularity");
  ASSERT_NE(s, nullptr);
  expect_no_allocation(*s, 6000 * kMs);
}

TEST(NoAllocationInCycle, Figure3JoinOfTwoCameras) {
  auto s = example("fig3_join.yaml", "joined");
  ASSERT_NE(s, nullptr);
  expect_no_allocation(*s, 2000 * kMs);
}

TEST(NoAllocationInCycle, BothRobotInterfacesHoldingForAnIllegalConfiguration) {
  auto s = example("visual_servo.yaml", "standard");
  ASSERT_NE(s, nullptr);
  s->table().set_illegal_configuration(true);  // robot_position holds
  expect_no_allocation(*s, 500 * kMs);
  s->table().set_illegal_configuration(false);
  expect_no_allocation(*s, 500 * kMs);  // and lets go
  auto f4 = fig4(ClockKind::kVirtual);
  f4->table().set_illegal_configuration(true);  // robot_torque holds
  expect_no_allocation(*f4, 500 * kMs);
  f4->table().set_illegal_configuration(false);
  expect_no_allocation(*f4, 500 * kMs);
}

// The detector detects: a module that allocates in cycle() is caught, and its task goes to ERROR.
class Allocating : public Module {
 public:
  static constexpr const char* kName = "allocating";
  static constexpr const char* kSummary = "allocates in cycle";
  static constexpr const char* kDoc = "a bad module";
  static void declare(Declarations&, const Params&) {}

 protected:
  Status cycle() override {
    std::vector<double> v(64);
    return v.empty() ? Status::fail("impossible") : Status::ok();
  }
};

TEST(NoAllocationInCycle, AnAllocatingModuleIsCaught) {
  Registry reg;
  ASSERT_TRUE(reg.add(testing::info_of<Allocating>()).ok());
  auto spec = load_subsystem_text("subsystem: alloc\ntasks:\n  - {name: a, module: allocating, period: 1ms}\n",
                                  "alloc.yaml", reg);
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  RunOptions o;
  o.clock = ClockKind::kVirtual;
  o.shm_suffix = testing::unique_suffix();
  auto s = Subsystem::create(*spec, reg, o);
  ASSERT_TRUE(s.ok());
  ASSERT_TRUE((*s)->start().ok());
  long allocations = 0;
  {
    AllocationGuard guard(AllocationGuard::OnNew::kFail);
    (*s)->run_for(5 * kMs);
    allocations = AllocationGuard::count();
  }
  EXPECT_GT(allocations, 0);
  EXPECT_EQ((*s)->snapshot()[0].state, TaskState::kError) << "the failed allocation is the module's fault";
}

}  // namespace
}  // namespace chimera
