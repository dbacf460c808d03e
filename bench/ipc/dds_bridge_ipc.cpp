// A state variable from one subsystem's table to another's through the DDS bridge (RemotePorts,
// docs/dds.md), against raw Cyclone DDS pub/sub of the very same message: the bridge's wire
// format (std_msgs/msg/Float64MultiArray with its two dimensions and the writer's stamp) and QoS
// (writer reliable, transient local, keep last 1; reader reliable, volatile, keep last 1), on the
// loopback interface. One transport per run, chosen by --transport raw|bridge, so that each is a
// process pair of its own (ipc_latency.hpp: the publisher a forked child, both SCHED_FIFO, pinned).
//
// The message (seq, two stamps, six doubles) travels as nine doubles: in the bridge's case it is
// written into the publisher's table as the f64[9] variable `bench_latest`, exported; the
// subscriber's bridge imports it into its own table, where the subscriber reads it as a task
// would. The publisher wakes its bridge as a task's publication of an exported variable does
// (Subsystem::watch_writes). Keys: dds_raw_array_latency_ns_p50/p99, dds_bridge_latency_ns_p50/p99.

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "chimera/dds/remote_ports.hpp"
#include "chimera/exec/write_watch.hpp"
#include "chimera/svt/global_table.hpp"
#include "dds/dds.h"
#include "float64_multi_array.h"
#include "ipc/ipc_latency.hpp"

namespace chimera::bench {
namespace {

using Msg = std_msgs_msg_dds__Float64MultiArray_;
using Dim = std_msgs_msg_dds__MultiArrayDimension_;

constexpr std::uint32_t kCount = 9;
constexpr const char* kVariable = "bench_latest";

std::array<double, kCount> pack(const Message& m) {
  std::array<double, kCount> v{static_cast<double>(m.seq), static_cast<double>(m.stamp_ns),
                               static_cast<double>(m.release_ns)};
  for (std::size_t i = 0; i < m.value.size(); ++i) v[3 + i] = m.value[i];
  return v;
}

// Exact: sequence numbers and CLOCK_MONOTONIC nanoseconds since boot are far below 2^53.
void unpack(const double* v, Message& m) {
  m.seq = static_cast<std::uint64_t>(v[0]);
  m.stamp_ns = static_cast<std::int64_t>(v[1]);
  m.release_ns = static_cast<std::int64_t>(v[2]);
  for (std::size_t i = 0; i < m.value.size(); ++i) m.value[i] = v[3 + i];
}

// ---- raw Cyclone DDS, the bridge's message and QoS ---------------------------------------------

struct RawSide {
  dds_entity_t participant;
  dds_entity_t topic = -1;
  explicit RawSide(int domain)
      : participant(dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr)) {
    if (participant < 0) return;
    topic = dds_create_topic(participant, &std_msgs_msg_dds__Float64MultiArray__desc,
                             (std::string("rt/") + kVariable).c_str(), nullptr, nullptr);
  }
  RawSide(const RawSide&) = delete;
  RawSide& operator=(const RawSide&) = delete;
  ~RawSide() {
    if (participant > 0) dds_delete(participant);
  }
};

dds_qos_t* group_qos(const std::string& partition) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_partition1(q, partition.c_str());
  return q;
}

struct RawPub {
  RawSide side;
  dds_entity_t writer = -1;
  std::string label = kVariable;
  std::uint64_t sequence = 0;
  RawPub(int domain, const std::string& partition) : side(domain) {
    if (side.topic < 0) return;
    dds_qos_t* g = group_qos(partition);
    const dds_entity_t publisher = dds_create_publisher(side.participant, g, nullptr);
    dds_delete_qos(g);
    dds_qos_t* q = dds_create_qos();
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    writer = dds_create_writer(publisher, side.topic, q, nullptr);
    dds_delete_qos(q);
  }
  [[nodiscard]] bool ready() const {
    dds_publication_matched_status_t st{};
    return dds_get_publication_matched_status(writer, &st) == DDS_RETCODE_OK && st.current_count > 0;
  }
  void publish(const Message& m) {
    std::array<double, kCount> values = pack(m);
    // The bridge's stamp, of the same length as its own: the same bytes on the wire.
    std::string stamp =
        "chimera:from=bench_bridge_pub;seq=" + std::to_string(++sequence) + ";t=" + std::to_string(m.stamp_ns);
    std::array<Dim, 2> dims{Dim{label.data(), kCount, kCount}, Dim{stamp.data(), 1, 1}};
    Msg msg{};
    msg.layout.dim._length = msg.layout.dim._maximum = 2;
    msg.layout.dim._buffer = dims.data();
    msg.data._length = msg.data._maximum = kCount;
    msg.data._buffer = values.data();
    dds_write(writer, &msg);
  }
};

struct RawSub {
  RawSide side;
  dds_entity_t reader = -1;
  RawSub(int domain, const std::string& partition) : side(domain) {
    if (side.topic < 0) return;
    dds_qos_t* g = group_qos(partition);
    const dds_entity_t subscriber = dds_create_subscriber(side.participant, g, nullptr);
    dds_delete_qos(g);
    dds_qos_t* q = dds_create_qos();
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    reader = dds_create_reader(subscriber, side.topic, q, nullptr);
    dds_delete_qos(q);
  }
  bool take_latest(Message& m) const {
    std::array<void*, 1> samples{nullptr};
    std::array<dds_sample_info_t, 1> info{};
    const dds_return_t n = dds_take(reader, samples.data(), info.data(), 1, 1);
    if (n <= 0) return false;
    const auto* msg = static_cast<const Msg*>(samples[0]);
    const bool ok = info[0].valid_data && msg->data._length == kCount;
    if (ok) unpack(msg->data._buffer, m);
    dds_return_loan(reader, samples.data(), n);
    return ok;
  }
};

// ---- through the bridge: table -> RemotePorts -> DDS -> RemotePorts -> table ---------------------

SubsystemSpec bridge_spec(const std::string& name, const std::string& partition, bool exports) {
  SubsystemSpec spec;
  spec.name = name;
  spec.dds.partition = partition;
  if (exports) {
    spec.exports.push_back(ExportSpec{kVariable, {}});
  } else {
    ImportSpec import;
    import.variable = kVariable;
    import.count = kCount;
    import.max_age_ns = 1'000'000'000;
    spec.imports.push_back(import);
  }
  return spec;
}

std::unique_ptr<GlobalTable> make_table(const std::string& name) {
  const VarSpec var{kVariable, VarShape{ElemType::kF64, kCount}};
  auto table = GlobalTable::create(name, std::span<const VarSpec>(&var, 1));
  if (!table) {
    std::fprintf(stderr, "%s\n", table.error().message.c_str());
    return nullptr;
  }
  return std::make_unique<GlobalTable>(std::move(*table));
}

std::unique_ptr<RemotePorts> make_bridge(const SubsystemSpec& spec, std::shared_ptr<WriteWatch> watch = nullptr) {
  RemotePortsOptions options;
  options.hold_when_stale = false;  // nothing here reads the flag
  options.exports_written = std::move(watch);
  auto ports = RemotePorts::create(spec, spec.name, options);
  if (!ports) {
    std::fprintf(stderr, "%s\n", ports.error().message.c_str());
    return nullptr;
  }
  return std::move(*ports);
}

struct BridgePub {
  std::unique_ptr<GlobalTable> table;
  std::shared_ptr<WriteWatch> watch = std::make_shared<WriteWatch>();
  std::unique_ptr<RemotePorts> ports;
  std::int64_t ready_at_ns = monotonic_ns() + 1'000'000'000;
  // The bridge says nothing of its readers: a second for discovery on loopback, and the
  // harness's warm-up messages after it, which are not recorded.
  [[nodiscard]] bool ready() const { return monotonic_ns() >= ready_at_ns; }
  void publish(const Message& m) {
    const std::array<double, kCount> values = pack(m);
    table->write(0, values.data());
    watch->written();  // as a task's publication of a watched variable does (Worker::run_job)
  }
};

struct BridgeSub {
  std::unique_ptr<GlobalTable> table;
  std::unique_ptr<RemotePorts> ports;
  std::uint64_t seen = 0;
  bool take_latest(Message& m) {
    std::array<double, kCount> values{};
    const ReadOutcome r = table->read(0, values.data(), seen);
    seen = r.version;
    if (r.freshness != Freshness::kNew) return false;
    unpack(values.data(), m);
    return true;
  }
};

}  // namespace
}  // namespace chimera::bench

int main(int argc, char** argv) {
  using namespace chimera;
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  const bool bridge = std::find(args.rest.begin(), args.rest.end(), "bridge") != args.rest.end();
  const IpcPlan plan = plan_for(args);
  // As dds_ipc: loopback only, unicast discovery, a domain of its own.
  use_cyclone_dds_on_loopback();
  const int domain = 100 + static_cast<int>(::getpid() % 100);
  const std::string id = std::to_string(::getpid());
  const std::string partition = "bench_bridge_" + id;
  if (!bridge) {
    IpcRun run = run_ipc_latency<RawPub, RawSub>(
        plan,
        [&]() -> std::unique_ptr<RawPub> {
          auto pub = std::make_unique<RawPub>(domain, partition);
          return pub->writer > 0 ? std::move(pub) : nullptr;
        },
        [&]() -> std::unique_ptr<RawSub> {
          auto sub = std::make_unique<RawSub>(domain, partition);
          return sub->reader > 0 ? std::move(sub) : nullptr;
        });
    return report_ipc(args, "dds_raw_array",
                      "Cyclone DDS 0.10.2, the bridge's Float64MultiArray and QoS, UDP on loopback", run, plan);
  }
  const std::string pub_name = "bench_bridge_pub_" + id;
  const std::string sub_name = "bench_bridge_sub_" + id;
  // The bridges read the domain from the file; the harness's domain for both.
  SubsystemSpec pub_spec = bridge_spec(pub_name, partition, true);
  SubsystemSpec sub_spec = bridge_spec(sub_name, partition, false);
  pub_spec.dds.domain = sub_spec.dds.domain = static_cast<std::uint32_t>(domain);
  IpcRun run = run_ipc_latency<BridgePub, BridgeSub>(
      plan,
      [&]() -> std::unique_ptr<BridgePub> {
        auto pub = std::make_unique<BridgePub>();
        pub->table = make_table(pub_name);
        if (!pub->table) return nullptr;
        pub->ports = make_bridge(pub_spec, pub->watch);
        return pub->ports ? std::move(pub) : nullptr;
      },
      [&]() -> std::unique_ptr<BridgeSub> {
        auto sub = std::make_unique<BridgeSub>();
        sub->table = make_table(sub_name);
        if (!sub->table) return nullptr;
        sub->ports = make_bridge(sub_spec);
        return sub->ports ? std::move(sub) : nullptr;
      });
  return report_ipc(args, "dds_bridge",
                    "table to table through two RemotePorts bridges (Cyclone DDS 0.10.2, UDP on loopback)", run, plan);
}
