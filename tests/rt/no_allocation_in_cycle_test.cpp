// The real-time path allocates nothing. While an AllocationGuard is armed every allocation is
// counted and operator new fails by throwing. Cycles of the framework (transfers, statistics,
// timing, dispatch) and of the library's modules run armed: Figure 4 on both clocks, its data
// logger included, Figures 8 and 9 (the kinematics, the damped least squares, the integrator, the
// camera, the position-mode robot), Figure 3's join, Figure 6's teleoperation, and both robot
// interfaces' hold while the illegal-configuration flag is raised.

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "control/subsystem_test_access.hpp"
#include "support/allocation_guard.hpp"
#include "support/probe_module.hpp"
#include "support/udp_sender.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

using testing::AllocationGuard;

// `record_seconds`: the flight recorder's history (chimera run keeps 10 s by default; 0 none).
std::unique_ptr<Subsystem> fig4(ClockKind clock, double record_seconds = 0) {
  auto spec = load_subsystem_file(CHIMERA_EXAMPLES_DIR "/fig4_pid_joint.yaml", Registry::global());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  RunOptions o;
  o.clock = clock;
  o.shm_suffix = testing::unique_suffix();
  o.realtime_priorities = false;
  o.record_seconds = record_seconds;
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

// The cycles all periodic tasks run in `ns` of virtual time, each at its own period.
std::uint64_t cycles_in(const Subsystem& s, std::int64_t ns) {
  std::uint64_t n = 0;
  for (const auto& t : s.snapshot())
    if (t.period_ns > 0) n += static_cast<std::uint64_t>(ns / t.period_ns);
  return n;
}

// The subsystem of `text` started on the virtual clock and run 10 ms (first touches); nullptr
// (and a test failure) if it does not load, create or start.
std::unique_ptr<Subsystem> started_virtual(const std::string& text) {
  auto spec = load_subsystem_text(text, "inline.yaml", Registry::global());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  if (!spec.ok()) return nullptr;
  RunOptions o;
  o.clock = ClockKind::kVirtual;
  o.shm_suffix = testing::unique_suffix();
  auto s = Subsystem::create(*spec, Registry::global(), o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  if (!s.ok() || !(*s)->start().ok()) return nullptr;
  (*s)->run_for(10 * kMs);
  return std::move(*s);
}

// Allocations in every thread while `s` runs for `ns`, with allocation made to fail.
long allocations_while_running(Subsystem& s, std::int64_t ns) {
  AllocationGuard guard(AllocationGuard::OnNew::kFail);
  s.run_for(ns);
  return AllocationGuard::count();
}

bool runs_module(const Subsystem& s, const std::string& module) {
  for (const auto& t : s.snapshot())
    if (t.module == module) return true;
  return false;
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
  EXPECT_EQ(total_cycles(*s) - before, cycles_in(*s, 2000 * kMs));
  EXPECT_TRUE(runs_module(*s, "data_logger")) << "the example logs its run, and this test covers the logger";
  for (const auto& t : s->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name;
}

// The flight recorder on, as chimera run has it by default: every output push and every cycle's
// end writes a ring record, and the rings are allocated once, before the tasks start.
TEST(NoAllocationInCycle, Figure4WithTheFlightRecorderOn) {
  auto s = fig4(ClockKind::kVirtual, 10.0);
  ASSERT_GT(s->recorded_seconds(), 0.0);
  s->run_for(100 * kMs);
  const auto before = total_cycles(*s);
  const long allocations = allocations_while_running(*s, 2000 * kMs);
  EXPECT_EQ(allocations, 0) << "allocations inside cycles with the recorder on";
  EXPECT_EQ(total_cycles(*s) - before, cycles_in(*s, 2000 * kMs));
  for (const auto& t : s->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name;
  // It did record: the dump holds every task's cycles of the last 2.1 s (a row each, and a header).
  const std::string dir = "/tmp/chimera-noalloc-dump-" + testing::unique_suffix();
  auto dumped = s->dump(dir, "test");
  ASSERT_TRUE(dumped.ok()) << dumped.error().message;
  std::ifstream timing(dir + "/timing.csv");
  const auto rows = std::count(std::istreambuf_iterator<char>(timing), std::istreambuf_iterator<char>(), '\n');
  EXPECT_GE(static_cast<std::uint64_t>(rows), total_cycles(*s)) << dir;
  std::filesystem::remove_all(dir);
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

// A ring of 16 rows fills at once: on the virtual clock the logger's cycle then waits for its
// writer thread, and neither allocates (the guard counts every thread).
TEST(NoAllocationInCycle, TheDataLoggerWithAFullRing) {
  const std::string log =
      (std::filesystem::temp_directory_path() / ("chimera_noalloc_" + std::to_string(::getpid()) + ".csv")).string();
  const std::string text = R"(subsystem: fig4_logged
tasks:
  - { name: traj, module: joint_traj_gen, period: 1ms }
  - { name: pid, module: pid_joint, period: 1ms }
  - { name: robot, module: robot_torque, period: 1ms }
  - name: log
    module: data_logger
    period: 1ms
    params: { variables: [theta_d, theta_m, tau_r], capacity: 16, file: )" +
                           log + " }\n";
  auto s = started_virtual(text);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(allocations_while_running(*s, 500 * kMs), 0) << "allocations while logging";
  s->stop();
  std::ifstream in(log);
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  EXPECT_EQ(lines, 1u + 510u) << "a header and a row for each cycle: none lost, none failed";
  std::filesystem::remove(log);
}

// Figure 6's own modules: a replayed session and a UDP socket (read every cycle, with commands
// arriving) feeding the Cartesian interpolation.
TEST(NoAllocationInCycle, TheTeleoperationModules) {
  auto s = started_virtual(R"(subsystem: teleop_alloc
constants:
  x_m: [0.5, 0, 0.5, 0, 0, 0.3]
tasks:
  - name: replay
    module: teleop_input
    period: 10ms
    params: { source: replay, session: ['0.1 move 0.05 0 0', '0.2 vel 0 0.1 0 0 0 0.2', '0.4 goto 0.4 0 0.6 0 0 0'] }
  - name: udp
    module: teleop_input
    period: 10ms
    rename: { x_goal: x_goal_udp, teleop_stats: udp_stats }
  - { name: interp, module: cartesian_interp, period: 1ms }
)");
  ASSERT_NE(s, nullptr);
  const auto port = s->get("udp_stats");
  ASSERT_TRUE(port.ok());
  const testing::UdpSender sender(static_cast<int>((*port)[2]));
  long allocations = 0;
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE(sender.send(i % 2 == 0 ? "move 0.01 0 0" : "nonsense"));
    allocations += allocations_while_running(*s, 100 * kMs);
  }
  EXPECT_EQ(allocations, 0) << "allocations while teleoperating";
  EXPECT_EQ(s->get("udp_stats")->at(0), 5.0) << "the datagrams were read";
  s->run_for(1000 * kMs);
  const auto x_d = s->get("x_d");
  ASSERT_TRUE(x_d.ok());
  EXPECT_NEAR((*x_d)[0], 0.4, 1e-12) << "the interpolation reached the replayed goto";
  EXPECT_NEAR((*x_d)[2], 0.6, 1e-12);
  for (const auto& t : s->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name;
}

TEST(NoAllocationInCycle, Figure4WithSensorNoise) {
  const char* text = R"(subsystem: fig4_noise
tasks:
  - { name: traj, module: joint_traj_gen, period: 1ms }
  - { name: pid, module: pid_joint, period: 1ms }
  - { name: robot, module: robot_torque, period: 1ms, params: { noise_std: 0.001 } }
)";
  auto s = started_virtual(text);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(allocations_while_running(*s, 500 * kMs), 0) << "allocations during 500 cycles of each task";
  EXPECT_EQ(total_cycles(*s), 3u * 510u);
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

TEST(NoAllocationInCycle, Figure6TeleoperationFromARecordedSession) {
  auto s = example("fig6_teleop.yaml", "replay");
  ASSERT_NE(s, nullptr);
  expect_no_allocation(*s, 8000 * kMs);  // every command of the session, on to home
}

TEST(NoAllocationInCycle, Figure6TeleoperationByResolvedRate) {
  auto s = example("fig6_teleop.yaml", "rate");
  ASSERT_NE(s, nullptr);
  expect_no_allocation(*s, 8000 * kMs);
}

TEST(NoAllocationInCycle, Figure3JoinOfTwoCameras) {
  auto s = example("fig3_join.yaml", "joined");
  ASSERT_NE(s, nullptr);
  expect_no_allocation(*s, 2000 * kMs);
}

TEST(NoAllocationInCycle, BothRobotInterfacesHoldingForAnIllegalConfiguration) {
  auto s = example("visual_servo.yaml", "standard");
  ASSERT_NE(s, nullptr);
  SubsystemTestAccess::table(*s).raise_illegal_configuration();  // robot_position holds
  expect_no_allocation(*s, 500 * kMs);
  SubsystemTestAccess::table(*s).lower_illegal_configuration();
  expect_no_allocation(*s, 500 * kMs);  // and lets go
  auto f4 = fig4(ClockKind::kVirtual);
  SubsystemTestAccess::table(*f4).raise_illegal_configuration();  // robot_torque holds
  expect_no_allocation(*f4, 500 * kMs);
  SubsystemTestAccess::table(*f4).lower_illegal_configuration();
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
