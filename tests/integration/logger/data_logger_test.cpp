// The data logger (modules/data_logger): what it writes for a subsystem on the virtual clock,
// exactly; that a small ring loses nothing there; how its ports take their sizes; its refusals;
// and a run on the real clock, where its writer thread works beside real-time tasks.

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"
#include "support/probe_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

/// ramp: x = [k, k/2, -k] and y = 10 k at its k-th cycle (k from 1), so that each row says
/// which cycle it saw.
class Ramp final : public Module {
 public:
  static constexpr const char* kName = "test_ramp";
  static constexpr const char* kSummary = "a ramp to log";
  static constexpr const char* kDoc = "x = [k, k/2, -k], y = 10 k";
  static void declare(Declarations& d, const Params&) {
    d.out_var("x", Dim::fixed(3), "ramps");
    d.out_var("y", Dim::fixed(1), "a ramp");
  }

 protected:
  Status init(InitContext& ctx) override {
    x_ = ctx.out<double>("x");
    y_ = ctx.out<double>("y");
    return Status::ok();
  }
  Status cycle() override {
    ++k_;
    x_[0] = k_;
    x_[1] = k_ / 2;
    x_[2] = -k_;
    y_[0] = 10 * k_;
    return Status::ok();
  }

 private:
  Out<double> x_;
  Out<double> y_;
  double k_ = 0;
};
CHIMERA_REGISTER_MODULE(Ramp);

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class DataLoggerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("chimera_logger_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // Loads `tasks` (the tasks: list of a file) and creates the subsystem; nullptr with the
  // message in error_ if either fails.
  std::unique_ptr<Subsystem> make(const std::string& tasks, ClockKind clock = ClockKind::kVirtual) {
    auto spec = load_subsystem_text("subsystem: logger\ntasks:\n" + tasks, "log.yaml", Registry::global());
    if (!spec) {
      error_ = spec.error().message;
      return nullptr;
    }
    spec_ = std::make_unique<SubsystemSpec>(*std::move(spec));
    RunOptions o;
    o.clock = clock;
    o.shm_suffix = testing::unique_suffix();
    o.realtime_priorities = false;
    auto s = Subsystem::create(*spec_, Registry::global(), o);
    if (!s) {
      error_ = s.error().message;
      return nullptr;
    }
    return std::move(*s);
  }

  // Runs `tasks` on the virtual clock for `ns`, stops (the writer drains the ring and closes the
  // file), and returns what the log `file` holds.
  std::string logged(const std::string& tasks, std::int64_t ns, const std::string& file) {
    auto s = make(tasks);
    if (s == nullptr) {
      ADD_FAILURE() << error_;
      return {};
    }
    EXPECT_TRUE(s->start().ok());
    s->run_for(ns);
    s->stop();
    return read_file(path(file));
  }

  std::filesystem::path dir_;
  std::unique_ptr<SubsystemSpec> spec_;
  std::string error_;
};

TEST_F(DataLoggerTest, WritesAHeaderAndOneRowACycleExactly) {
  const std::string log = logged(
      "  - { name: ramp, module: test_ramp, period: 10ms }\n"
      "  - { name: log, module: data_logger, period: 10ms, params: { variables: [x, y], file: " +
          path("run.csv") + " } }\n",
      45 * kMs, "run.csv");  // releases at 0, 10, 20, 30 and 40 ms
  // At a shared release the ramp runs first (data-flow order): each row sees that instant's ramp.
  EXPECT_EQ(log,
            "t,x[0],x[1],x[2],y\n"
            "0,1,0.5,-1,10\n"
            "0.01,2,1,-2,20\n"
            "0.02,3,1.5,-3,30\n"
            "0.03,4,2,-4,40\n"
            "0.04,5,2.5,-5,50\n");
}

TEST_F(DataLoggerTest, ASlowerLoggerSamplesAndRenamedPortsNameTheirColumns) {
  const std::string log = logged(
      "  - { name: ramp, module: test_ramp, period: 10ms }\n"
      "  - name: log\n    module: data_logger\n    period: 20ms\n"
      "    params: { variables: [position], file: " +
          path("slow.csv") + " }\n    rename: { position: x }\n",
      45 * kMs, "slow.csv");
  EXPECT_EQ(log,
            "t,position[0],position[1],position[2]\n"
            "0,1,0.5,-1\n"
            "0.02,3,1.5,-3\n"
            "0.04,5,2.5,-5\n");
}

TEST_F(DataLoggerTest, OnTheVirtualClockASmallRingLosesNothing) {
  const auto lines = lines_of(
      logged("  - { name: ramp, module: test_ramp, period: 1ms }\n"
             "  - { name: log, module: data_logger, period: 1ms, params: { variables: [y], capacity: 4, file: " +
                 path("all.csv") + " } }\n",
             2000 * kMs, "all.csv"));
  ASSERT_EQ(lines.size(), 2001u) << "a header and 2000 rows";
  for (std::size_t k = 1; k < lines.size(); k += 499) {
    std::ostringstream expected;
    expected << static_cast<double>(k - 1) * 1e-3 << "," << 10 * k;
    EXPECT_EQ(lines[k], expected.str()) << "row " << k;
  }
  EXPECT_EQ(lines.back(), "1.999,20000");
}

TEST_F(DataLoggerTest, CHIMERA_LOG_DIRHoldsRelativeFilesAndTheTaskNamesTheDefault) {
  auto s = make(
      "  - { name: ramp, module: test_ramp, period: 10ms }\n"
      "  - { name: arm_log, module: data_logger, period: 10ms, params: { variables: [y] } }\n");
  ASSERT_NE(s, nullptr) << error_;
  ::setenv("CHIMERA_LOG_DIR", dir_.c_str(), 1);  // NOLINT(concurrency-mt-unsafe): virtual clock, one thread
  const auto started = s->start();               // init reads it
  ::unsetenv("CHIMERA_LOG_DIR");                 // NOLINT(concurrency-mt-unsafe): same
  ASSERT_TRUE(started.ok());
  s->run_for(5 * kMs);
  s->stop();
  EXPECT_EQ(read_file(path("arm_log.csv")), "t,y\n0,10\n");
}

TEST_F(DataLoggerTest, AVariableWithNoSizeAnywhereIsAViolation) {
  auto s = make("  - { name: log, module: data_logger, period: 10ms, params: { variables: [nothing] } }\n");
  ASSERT_EQ(s, nullptr);
  EXPECT_NE(error_.find("port nothing of task log takes its size from variable nothing"), std::string::npos) << error_;
}

TEST_F(DataLoggerTest, RefusesToStartWithoutVariablesOrAWritableFile) {
  auto none = make("  - { name: log, module: data_logger, period: 10ms }\n");
  ASSERT_NE(none, nullptr) << error_;
  auto started = none->start();
  ASSERT_FALSE(started.ok());
  EXPECT_NE(started.error().message.find("give variables: [names] to record"), std::string::npos)
      << started.error().message;

  auto unwritable = make(
      "  - { name: ramp, module: test_ramp, period: 10ms }\n"
      "  - { name: log, module: data_logger, period: 10ms, params: { variables: [y], file: " +
      path("no/such/dir/x.csv") + " } }\n");
  ASSERT_NE(unwritable, nullptr) << error_;
  started = unwritable->start();
  ASSERT_FALSE(started.ok());
  EXPECT_NE(
      started.error().message.find("cannot write the log " + path("no/such/dir/x.csv") + ": No such file or directory"),
      std::string::npos)
      << started.error().message;
}

TEST_F(DataLoggerTest, RunsBesideRealTimeTasksOnTheRealClock) {
  auto s = make(
      "  - { name: ramp, module: test_ramp, period: 1ms }\n"
      "  - { name: log, module: data_logger, period: 1ms, params: { variables: [x, y], capacity: 100000, "
      "file: " +
          path("real.csv") + " } }\n",
      ClockKind::kReal);
  ASSERT_NE(s, nullptr) << error_;
  ASSERT_TRUE(s->start().ok());
  s->run_for(200 * kMs);
  s->stop();
  const auto cycles = s->snapshot()[1].stats.cycles;
  const auto lines = lines_of(read_file(path("real.csv")));
  ASSERT_GE(lines.size(), 2u);
  EXPECT_EQ(lines[0], "t,x[0],x[1],x[2],y");
  // The ring holds far more rows than the run has cycles, so however late the writer ran, no
  // row was dropped: every cycle left one.
  EXPECT_EQ(lines.size() - 1, cycles);
  double previous = -1;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const double t = std::stod(lines[i].substr(0, lines[i].find(',')));
    EXPECT_GT(t, previous) << "row " << i;
    previous = t;
    std::istringstream row(lines[i]);
    std::string cell;
    int cells = 0;
    while (std::getline(row, cell, ',')) ++cells;
    EXPECT_EQ(cells, 5) << lines[i];
  }
}

}  // namespace
}  // namespace chimera
