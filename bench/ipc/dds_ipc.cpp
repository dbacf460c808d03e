// The latest value from one process to another through Cyclone DDS 0.10 (Debian's package) on
// the loopback interface: UDP unicast to 127.0.0.1, no multicast, no shared memory transport.
// QoS: reliable, keep last 1 on both sides (a state variable's latest-value semantics; the
// default reliability of ROS 2). Keys: dds_latency_ns_p50, dds_latency_ns_p99.

#include <unistd.h>

#include <cstdlib>
#include <string>

#include "dds/dds.h"
#include "ipc/ipc_latency.hpp"
#include "latest_value.h"

namespace chimera::bench {
namespace {

static_assert(sizeof(chimera_bench_LatestValue) == sizeof(Message));

constexpr const char* kTopic = "chimera_bench_latest_value";

/// One participant with the benchmark's topic and QoS.
class Participant {
 public:
  explicit Participant(int domain) {
    participant_ = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
    if (participant_ < 0) return;
    topic_ = dds_create_topic(participant_, &chimera_bench_LatestValue_desc, kTopic, nullptr, nullptr);
    qos_ = dds_create_qos();
    dds_qset_reliability(qos_, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(qos_, DDS_HISTORY_KEEP_LAST, 1);
  }
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;
  ~Participant() {
    if (qos_ != nullptr) dds_delete_qos(qos_);
    if (participant_ > 0) dds_delete(participant_);  // deletes its topic, readers and writers
  }
  [[nodiscard]] bool ok() const { return participant_ > 0 && topic_ > 0; }
  [[nodiscard]] dds_entity_t participant() const { return participant_; }
  [[nodiscard]] dds_entity_t topic() const { return topic_; }
  [[nodiscard]] const dds_qos_t* qos() const { return qos_; }

 private:
  dds_entity_t participant_ = -1;
  dds_entity_t topic_ = -1;
  dds_qos_t* qos_ = nullptr;
};

struct DdsPub {
  Participant p;
  dds_entity_t writer;
  explicit DdsPub(int domain)
      : p(domain), writer(p.ok() ? dds_create_writer(p.participant(), p.topic(), p.qos(), nullptr) : -1) {}
  bool ready() {
    dds_publication_matched_status_t st{};
    return dds_get_publication_matched_status(writer, &st) == DDS_RETCODE_OK && st.current_count > 0;
  }
  void publish(const Message& m) { dds_write(writer, &m); }
};

struct DdsSub {
  Participant p;
  dds_entity_t reader;
  explicit DdsSub(int domain)
      : p(domain), reader(p.ok() ? dds_create_reader(p.participant(), p.topic(), p.qos(), nullptr) : -1) {}
  bool take_latest(Message& m) {
    chimera_bench_LatestValue sample{};
    void* samples[1] = {&sample};
    dds_sample_info_t info[1];
    const dds_return_t n = dds_take(reader, samples, info, 1, 1);
    if (n <= 0 || !info[0].valid_data) return false;
    m.seq = sample.seq;
    m.stamp_ns = sample.stamp_ns;
    m.release_ns = sample.release_ns;
    for (std::size_t i = 0; i < m.value.size(); ++i) m.value[i] = sample.value[i];
    return true;
  }
};

}  // namespace
}  // namespace chimera::bench

int main(int argc, char** argv) {
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  const IpcPlan plan = plan_for(args);
  // Loopback only, unicast discovery; a domain of its own so that no other DDS program here
  // (ROS 2, another run) joins in.
  use_cyclone_dds_on_loopback();
  const int domain = 100 + static_cast<int>(::getpid() % 100);
  IpcRun run = run_ipc_latency<DdsPub, DdsSub>(
      plan,
      [&]() -> std::unique_ptr<DdsPub> {
        auto pub = std::make_unique<DdsPub>(domain);
        return pub->writer > 0 ? std::move(pub) : nullptr;
      },
      [&]() -> std::unique_ptr<DdsSub> {
        auto sub = std::make_unique<DdsSub>(domain);
        return sub->reader > 0 ? std::move(sub) : nullptr;
      });
  return report_ipc(args, "dds", "Cyclone DDS 0.10.2 (Debian), UDP on loopback, reliable, keep last 1", run, plan);
}
