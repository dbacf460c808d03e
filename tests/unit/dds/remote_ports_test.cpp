// Two subsystems' bridges in one process, each test on a DDS partition of its own: a variable
// exported by one lands in the other's table with its writer's stamp; it goes stale, and raises
// the illegal-configuration flag, when the publisher stops; a remote of the wrong size is refused
// and named. Waits are bounded generously and only wait for what must happen; nothing is timed.

#include "chimera/dds/remote_ports.hpp"

#include <unistd.h>

#include <array>
#include <chrono>
#include <functional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "chimera/svt/global_table.hpp"

namespace chimera {
namespace {

// Long enough for discovery on a loaded machine; a failing wait ends the test, a passing one is quick.
bool eventually(const std::function<bool()>& condition) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return condition();
}

std::string unique(const std::string& what) {
  const auto* test = testing::UnitTest::GetInstance()->current_test_info();
  return what + "_" + test->name() + "_" + std::to_string(getpid());
}

// One side: a table with one f64 variable, and the file that exports or imports it.
struct Side {
  SubsystemSpec spec;
  GlobalTable table;
  VarIndex index = 0;

  static Side make(const std::string& name, std::uint32_t count, const std::string& partition) {
    const VarSpec var{"x_d", VarShape{ElemType::kF64, count}};
    auto table = GlobalTable::create(name, std::span<const VarSpec>(&var, 1));
    EXPECT_TRUE(table.ok()) << table.error().message;
    Side side{SubsystemSpec{}, std::move(*table), 0};
    side.spec.name = name;
    side.spec.dds.partition = partition;
    side.index = *side.table.find("x_d");
    return side;
  }
};

Side exporter(std::uint32_t count) {
  Side side = Side::make(unique("vision"), count, unique("part"));
  side.spec.exports.push_back(ExportSpec{"x_d", {}});
  return side;
}

Side importer(std::uint32_t count) {
  Side side = Side::make(unique("robot"), count, unique("part"));
  ImportSpec import;
  import.variable = "x_d";
  import.count = count;
  import.max_age_ns = 50'000'000;
  import.durability = DdsDurability::kTransientLocal;
  side.spec.imports.push_back(import);
  return side;
}

std::unique_ptr<RemotePorts> bridge(const Side& side) {
  auto ports = RemotePorts::create(side.spec, side.spec.name);
  EXPECT_TRUE(ports.ok()) << ports.error().message;
  if (!ports.ok()) return nullptr;
  return std::move(*ports);
}

TEST(RemotePorts, AnExportLandsInTheImportersTableWithItsStamp) {
  Side vision = exporter(6);
  Side robot = importer(6);
  auto out = bridge(vision);
  auto in = bridge(robot);
  ASSERT_TRUE(out && in);
  const std::array<double, 6> pose{0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  vision.table.write(vision.index, pose.data());

  ASSERT_TRUE(eventually([&] { return in->imports().front().samples >= 1; }));
  std::array<double, 6> got{};
  const ReadOutcome read = robot.table.read(robot.index, got.data(), 0);
  EXPECT_EQ(read.freshness, Freshness::kNew);
  EXPECT_EQ(got, pose);
  const ImportStatus status = in->imports().front();
  EXPECT_EQ(status.variable, "x_d");
  EXPECT_EQ(status.writer, vision.spec.name);
  EXPECT_EQ(status.writer_sequence, 1U);
  EXPECT_GT(status.writer_time_ns, 0);
  EXPECT_EQ(status.refused, 0U);

  // A new value, a new sample: the latest value, never a queue.
  const std::array<double, 6> next{1, 2, 3, 4, 5, 6};
  vision.table.write(vision.index, next.data());
  ASSERT_TRUE(eventually([&] { return in->imports().front().writer_sequence == 2; }));
  robot.table.read(robot.index, got.data(), 0);
  EXPECT_EQ(got, next);
  EXPECT_TRUE(in->take_errors().empty());
}

TEST(RemotePorts, AnImportGoesStaleAndHoldsTheFlagWhenThePublisherStops) {
  Side vision = exporter(6);
  Side robot = importer(6);
  auto in = bridge(robot);
  ASSERT_TRUE(in);
  // Nothing received yet: stale once max_age has passed since the bridge started, flag raised.
  ASSERT_TRUE(eventually([&] { return robot.table.illegal_configuration(); }));
  EXPECT_TRUE(in->imports().front().stale);

  auto out = bridge(vision);
  const std::array<double, 6> pose{1, 1, 1, 1, 1, 1};
  vision.table.write(vision.index, pose.data());
  // While the publisher writes within max_age, the import stays fresh and the flag comes down.
  ASSERT_TRUE(eventually([&] {
    vision.table.write(vision.index, pose.data());
    return !in->imports().front().stale && !robot.table.illegal_configuration();
  }));

  out.reset();  // the vision machine drops off
  ASSERT_TRUE(eventually([&] { return in->imports().front().stale; }));
  EXPECT_TRUE(robot.table.illegal_configuration());
  // Readers see old data: nothing newer than what they hold.
  std::array<double, 6> got{};
  const ReadOutcome first = robot.table.read(robot.index, got.data(), 0);
  EXPECT_EQ(robot.table.read(robot.index, got.data(), first.version).freshness, Freshness::kOld);
  EXPECT_EQ(got, pose);

  in.reset();  // the bridge's hold goes with it
  EXPECT_FALSE(robot.table.illegal_configuration());
}

TEST(RemotePorts, ARemoteOfTheWrongSizeIsRefusedAndNamed) {
  Side vision = exporter(7);
  Side robot = importer(6);
  auto out = bridge(vision);
  auto in = bridge(robot);
  ASSERT_TRUE(out && in);
  const std::array<double, 7> wrong{1, 2, 3, 4, 5, 6, 7};
  vision.table.write(vision.index, wrong.data());

  std::vector<std::string> errors;
  ASSERT_TRUE(eventually([&] {
    auto more = in->take_errors();
    errors.insert(errors.end(), more.begin(), more.end());
    return !errors.empty();
  }));
  ASSERT_EQ(errors.size(), 1U);
  EXPECT_EQ(errors[0], "import x_d: subsystem " + robot.spec.name + " reads f64[6] but subsystem " +
                           vision.spec.name + " publishes f64[7] on rt/x_d; its samples are refused");
  const ImportStatus status = in->imports().front();
  EXPECT_GE(status.refused, 1U);
  EXPECT_EQ(status.samples, 0U);
  EXPECT_EQ(robot.table.version(robot.index), 0U);  // never written: no garbage
  // More wrong samples are counted, not reported again.
  vision.table.write(vision.index, wrong.data());
  ASSERT_TRUE(eventually([&] { return in->imports().front().refused >= 2; }));
  EXPECT_TRUE(in->take_errors().empty());
}

TEST(RemotePorts, TwoSubsystemsExportingOneVariableAreRefusedByBoth) {
  Side vision = exporter(6);
  Side other = Side::make(unique("other"), 6, unique("part"));
  other.spec.exports.push_back(ExportSpec{"x_d", {}});
  auto a = bridge(vision);
  auto b = bridge(other);
  ASSERT_TRUE(a && b);
  const std::array<double, 6> pose{1, 2, 3, 4, 5, 6};
  std::vector<std::string> from_a;
  std::vector<std::string> from_b;
  ASSERT_TRUE(eventually([&] {
    vision.table.write(vision.index, pose.data());
    other.table.write(other.index, pose.data());
    for (auto& e : a->take_errors()) from_a.push_back(e);
    for (auto& e : b->take_errors()) from_b.push_back(e);
    return !from_a.empty() && !from_b.empty();
  }));
  EXPECT_EQ(from_a.front(), "rule 1: x_d is exported by subsystem " + vision.spec.name + " and by subsystem " +
                                other.spec.name + " on rt/x_d; the illegal-configuration flag stays raised");
  EXPECT_EQ(from_b.front(), "rule 1: x_d is exported by subsystem " + other.spec.name + " and by subsystem " +
                                vision.spec.name + " on rt/x_d; the illegal-configuration flag stays raised");
  EXPECT_TRUE(vision.table.illegal_configuration());
  EXPECT_TRUE(other.table.illegal_configuration());
}

TEST(RemotePorts, AnExporterAloneRaisesNothing) {
  Side vision = exporter(6);
  auto a = bridge(vision);
  ASSERT_TRUE(a);
  const std::array<double, 6> pose{1, 2, 3, 4, 5, 6};
  vision.table.write(vision.index, pose.data());
  // Its own samples never reach its echo (it ignores its own participant); by the time an
  // importer has the sample, local delivery has long reached every reader of this process.
  Side robot = importer(6);
  auto in = bridge(robot);
  ASSERT_TRUE(in);
  ASSERT_TRUE(eventually([&] { return in->imports().front().samples >= 1; }));
  EXPECT_TRUE(a->take_errors().empty());
  EXPECT_FALSE(vision.table.illegal_configuration());
}

TEST(RemotePorts, AnImportOfAnotherShapeThanTheTableIsRefusedAtCreate) {
  Side robot = importer(6);
  robot.spec.imports.front().count = 5;
  auto ports = RemotePorts::create(robot.spec, robot.spec.name);
  ASSERT_FALSE(ports.ok());
  EXPECT_EQ(ports.error().message, "import x_d: the table holds it as f64[6], not f64[5]");
}

}  // namespace
}  // namespace chimera
