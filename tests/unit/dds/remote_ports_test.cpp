// Two subsystems' bridges in one process, each test on a DDS partition of its own: a variable
// exported by one lands in the other's table with its writer's stamp; it goes stale, and raises
// the illegal-configuration flag, when the publisher stops; a remote of the wrong size is refused
// and named. Waits are bounded generously and only wait for what must happen; nothing is timed.

#include "chimera/dds/remote_ports.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <dds/dds.h>
#include <gtest/gtest.h>

#include "chimera/svt/global_table.hpp"
#include "float64_multi_array.h"
#include "ros_string.h"

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
  EXPECT_GE(status.age_ns, 0);
  EXPECT_EQ(status.max_age_ns, 50'000'000);
  EXPECT_EQ(status.refusal, "");

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
  // Nothing received yet: stale from the start (never received is not fresh), the flag raised
  // before create returns, so no task reads the import's zeros as a value.
  EXPECT_TRUE(robot.table.illegal_configuration());
  EXPECT_TRUE(in->imports().front().stale);
  EXPECT_EQ(in->imports().front().samples, 0U);

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

// A writer as a ROS 2 node makes one: a plain Float64MultiArray on rt/x_d, no Chimera stamp and
// no shape in its user data, reliable and keep last 1 (so a flood replaces, never blocks).
struct RawWriter {
  dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, nullptr, nullptr);
  dds_entity_t writer = 0;

  explicit RawWriter(const std::string& partition) {
    dds_qos_t* qos = dds_create_qos();
    dds_qset_partition1(qos, partition.c_str());
    const dds_entity_t publisher = dds_create_publisher(participant, qos, nullptr);
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);  // what importer() asks for
    const dds_entity_t topic =
        dds_create_topic(participant, &std_msgs_msg_dds__Float64MultiArray__desc, "rt/x_d", nullptr, nullptr);
    writer = dds_create_writer(publisher, topic, qos, nullptr);
    dds_delete_qos(qos);
    EXPECT_GT(writer, 0);
  }
  ~RawWriter() { dds_delete(participant); }
  RawWriter(const RawWriter&) = delete;
  RawWriter& operator=(const RawWriter&) = delete;

  void write(std::vector<double> values, std::uint32_t data_offset = 0) const {
    std::string label = "x_d";
    std_msgs_msg_dds__MultiArrayDimension_ dim{label.data(), static_cast<std::uint32_t>(values.size()),
                                               static_cast<std::uint32_t>(values.size())};
    std_msgs_msg_dds__Float64MultiArray_ msg{};
    msg.layout.dim._length = msg.layout.dim._maximum = 1;
    msg.layout.dim._buffer = &dim;
    msg.layout.data_offset = data_offset;
    msg.data._length = msg.data._maximum = static_cast<std::uint32_t>(values.size());
    msg.data._buffer = values.data();
    EXPECT_EQ(dds_write(writer, &msg), DDS_RETCODE_OK);
  }
};

// A ROS 2 node publishing std_msgs/msg/String on an import's topic: DDS never matches it with the
// importer's reader, whose type is another.
struct TextWriter {
  dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, nullptr, nullptr);
  dds_entity_t writer = 0;

  TextWriter(const std::string& partition, const std::string& topic_name) {
    dds_qos_t* qos = dds_create_qos();
    dds_qset_partition1(qos, partition.c_str());
    const dds_entity_t publisher = dds_create_publisher(participant, qos, nullptr);
    dds_delete_qos(qos);
    const dds_entity_t topic =
        dds_create_topic(participant, &std_msgs_msg_dds__String__desc, topic_name.c_str(), nullptr, nullptr);
    writer = dds_create_writer(publisher, topic, nullptr, nullptr);
    EXPECT_GT(writer, 0);
  }
  ~TextWriter() { dds_delete(participant); }
  TextWriter(const TextWriter&) = delete;
  TextWriter& operator=(const TextWriter&) = delete;

  void write(std::string text) const {
    std_msgs_msg_dds__String_ msg{text.data()};
    EXPECT_EQ(dds_write(writer, &msg), DDS_RETCODE_OK);
  }
};

std::vector<std::string> collect_errors(RemotePorts& ports, std::vector<std::string>& errors) {
  auto more = ports.take_errors();
  errors.insert(errors.end(), more.begin(), more.end());
  return errors;
}

// A writer that says nothing of its shape (a ROS 2 node) is checked sample by sample.
// Equation 2's type across machines: a writer of another type on an import's topic is named when it
// is discovered (DDS would deliver none of its samples, and the import would only stay stale);
// `status` keeps the refusal beside the import. One of the wire format's type in another
// partition, or on another topic, is no concern of this import.
TEST(RemotePorts, AWriterOfAnotherTypeOnAnImportsTopicIsNamedAtDiscovery) {
  Side robot = importer(6);
  auto in = bridge(robot);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->imports().front().age_ns, -1);  // no sample yet
  const TextWriter elsewhere(unique("other_part"), "rt/x_d");
  const TextWriter other_topic(robot.spec.dds.partition, "rt/y_d");
  const TextWriter ros_node(robot.spec.dds.partition, "rt/x_d");
  std::vector<std::string> errors;
  ASSERT_TRUE(eventually([&] { return !collect_errors(*in, errors).empty(); }));
  ros_node.write("hello");
  other_topic.write("hello");
  elsewhere.write("hello");
  const std::string named = "import x_d: subsystem " + robot.spec.name +
                            " reads std_msgs/msg/Float64MultiArray but a writer without a Chimera stamp (a ROS 2 "
                            "node?) publishes std_msgs/msg/String on rt/x_d; DDS delivers none of its samples";
  ASSERT_EQ(errors.size(), 1U) << errors.back();
  EXPECT_EQ(errors[0], named);
  // The other two were discovered as well by now (one participant's discovery is not slower than
  // another's on one machine); give them the time a third writer takes to be heard.
  const TextWriter third(robot.spec.dds.partition, "rt/x_d");
  ASSERT_TRUE(eventually([&] { return collect_errors(*in, errors).size() >= 2; }));
  EXPECT_EQ(errors.size(), 2U);
  EXPECT_EQ(errors[1], named);  // the third, a writer of its own
  const ImportStatus status = in->imports().front();
  EXPECT_EQ(status.refusal, named);
  EXPECT_EQ(status.samples, 0U);
  EXPECT_TRUE(status.stale);
  EXPECT_EQ(robot.table.version(robot.index), 0U);
}

TEST(RemotePorts, AWriterWithoutAStampOfTheWrongSizeIsRefusedSampleBySample) {
  Side robot = importer(6);
  auto in = bridge(robot);
  ASSERT_TRUE(in);
  const RawWriter ros_node(robot.spec.dds.partition);
  ASSERT_TRUE(eventually([&] {
    ros_node.write({1, 2, 3, 4, 5, 6, 7});
    return in->imports().front().refused >= 1;
  }));
  std::vector<std::string> errors;
  collect_errors(*in, errors);
  ASSERT_EQ(errors.size(), 1U);
  const std::string head = "import x_d: subsystem " + robot.spec.name +
                           " reads f64[6] but a writer without a Chimera stamp (a ROS 2 node?), instance ";
  EXPECT_TRUE(errors[0].starts_with(head)) << errors[0];
  EXPECT_TRUE(errors[0].ends_with(" publishes f64[7] on rt/x_d; its samples are refused")) << errors[0];
  EXPECT_EQ(in->imports().front().samples, 0U);
  EXPECT_EQ(robot.table.version(robot.index), 0U);  // never written: no garbage
  // More wrong samples are counted, not reported again.
  const std::uint64_t before = in->imports().front().refused;
  ASSERT_TRUE(eventually([&] {
    ros_node.write({1, 2, 3, 4, 5, 6, 7});
    return in->imports().front().refused > before;
  }));
  EXPECT_TRUE(in->take_errors().empty());
  EXPECT_EQ(robot.table.version(robot.index), 0U);
}

// A ROS 2 node can publish into an import; data_offset is honoured, and an offset past the data
// (a malformed layout, though valid CDR) is refused as having no values.
TEST(RemotePorts, ARos2NodeCanPublishIntoAnImportAndAMalformedLayoutIsRefused) {
  Side robot = importer(6);
  auto in = bridge(robot);
  ASSERT_TRUE(in);
  const RawWriter ros_node(robot.spec.dds.partition);
  ASSERT_TRUE(eventually([&] {
    ros_node.write({1, 2, 3, 4, 5, 6}, 10);
    return in->imports().front().refused >= 1;
  }));
  std::vector<std::string> errors;
  collect_errors(*in, errors);
  ASSERT_EQ(errors.size(), 1U);
  EXPECT_TRUE(errors[0].ends_with(" publishes f64[0] on rt/x_d; its samples are refused")) << errors[0];
  EXPECT_EQ(robot.table.version(robot.index), 0U);

  ASSERT_TRUE(eventually([&] {
    ros_node.write({-1, -2, 1, 2, 3, 4, 5, 6}, 2);
    return in->imports().front().samples >= 1;
  }));
  std::array<double, 6> got{};
  robot.table.read(robot.index, got.data(), 0);
  EXPECT_EQ(got, (std::array<double, 6>{1, 2, 3, 4, 5, 6}));
  const ImportStatus status = in->imports().front();
  EXPECT_EQ(status.writer, "");  // no Chimera stamp
  EXPECT_EQ(status.writer_sequence, 0U);
  EXPECT_GT(status.writer_time_ns, 0);  // DDS's source timestamp instead
  const auto changes = in->take_changes();
  EXPECT_NE(std::find(changes.begin(), changes.end(),
                      "import x_d: first sample, from a writer without a Chimera stamp (a ROS 2 node?)"),
            changes.end());
}

// A flood of samples is taken as the latest value: never queued, and the bridge keeps up with
// whatever comes last.
TEST(RemotePorts, AFloodOfSamplesEndsAtTheLatestValue) {
  Side robot = importer(6);
  auto in = bridge(robot);
  ASSERT_TRUE(in);
  const RawWriter ros_node(robot.spec.dds.partition);
  ASSERT_TRUE(eventually([&] {
    ros_node.write({0, 0, 0, 0, 0, 0});
    return in->imports().front().samples >= 1;
  }));
  constexpr int kFlood = 20'000;
  for (int i = 1; i <= kFlood; ++i) ros_node.write(std::vector<double>(6, static_cast<double>(i)));
  std::array<double, 6> got{};
  ASSERT_TRUE(eventually([&] {
    robot.table.read(robot.index, got.data(), 0);
    return got[0] == kFlood;
  })) << "the import holds "
      << got[0];
  EXPECT_EQ(got, (std::array<double, 6>{kFlood, kFlood, kFlood, kFlood, kFlood, kFlood}));
  EXPECT_LE(in->imports().front().samples, static_cast<std::uint64_t>(kFlood) + 1);
  EXPECT_TRUE(in->take_errors().empty());
  EXPECT_FALSE(in->imports().front().stale);
}

// A Chimera writer says its shape when it is discovered: the mismatch is named before any sample.
TEST(RemotePorts, ARemoteOfTheWrongSizeIsNamedAtDiscoveryBeforeAnySample) {
  Side vision = exporter(7);
  Side robot = importer(6);
  auto out = bridge(vision);
  auto in = bridge(robot);
  ASSERT_TRUE(out && in);
  std::vector<std::string> errors;
  ASSERT_TRUE(eventually([&] {
    auto more = in->take_errors();
    errors.insert(errors.end(), more.begin(), more.end());
    return !errors.empty();
  }));
  ASSERT_EQ(errors.size(), 1U);
  EXPECT_EQ(errors[0], "import x_d: subsystem " + robot.spec.name + " reads f64[6] but subsystem " + vision.spec.name +
                           " publishes f64[7] on rt/x_d; its samples are refused");
  EXPECT_EQ(vision.table.version(vision.index), 0U);  // nothing was ever written, nor sent
  EXPECT_EQ(in->imports().front().refused, 0U);
  // Its first sample is refused too, and not named a second time.
  const std::array<double, 7> wrong{1, 2, 3, 4, 5, 6, 7};
  vision.table.write(vision.index, wrong.data());
  ASSERT_TRUE(eventually([&] { return in->imports().front().refused >= 1; }));
  EXPECT_TRUE(in->take_errors().empty());
  EXPECT_EQ(robot.table.version(robot.index), 0U);
}

// What an operator is told as it happens: the first sample, stale, fresh again.
TEST(RemotePorts, AnImportsChangesAreToldOnceEach) {
  Side vision = exporter(6);
  Side robot = importer(6);
  auto in = bridge(robot);
  ASSERT_TRUE(in);
  std::vector<std::string> changes;
  auto collect = [&] {
    for (auto& c : in->take_changes()) changes.push_back(c);
  };
  ASSERT_TRUE(eventually([&] {
    collect();
    return !changes.empty();
  }));
  // The taker judges every 5 ms (max_age / 10): twenty judgements later, still the one change.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  collect();
  ASSERT_EQ(changes.size(), 1U);
  EXPECT_EQ(changes[0], "import x_d: stale, no sample yet: the illegal-configuration flag is raised");

  auto out = bridge(vision);
  const std::array<double, 6> pose{1, 1, 1, 1, 1, 1};
  ASSERT_TRUE(eventually([&] {
    vision.table.write(vision.index, pose.data());
    collect();
    return changes.size() >= 3;
  }));
  EXPECT_EQ(changes[1], "import x_d: first sample, from subsystem " + vision.spec.name);
  EXPECT_EQ(changes[2], "import x_d: fresh again, from subsystem " + vision.spec.name);
  // Whatever a loaded machine's stalls do to a 50 ms max_age, stale and fresh alternate.
  for (int i = 0; i < 20; ++i) {
    vision.table.write(vision.index, pose.data());
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  collect();
  for (std::size_t i = 3; i < changes.size(); ++i)
    EXPECT_EQ(changes[i].starts_with("import x_d: stale"), changes[i - 1].starts_with("import x_d: fresh"))
        << changes[i];
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
