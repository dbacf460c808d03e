// The bridge to other subsystems: two ordinary threads between the global table and Cyclone DDS.
// The publisher polls the exports' versions and writes what changed; the taker waits on the
// imports' readers, writes each sample's values into the table and judges staleness. Only they,
// create() and the destructor call DDS.

#include "chimera/dds/remote_ports.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <dds/dds.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/core/duration_text.hpp"
#include "chimera/svt/global_table.hpp"
#include "float64_multi_array.h"
#include "sample_stamp.hpp"

namespace chimera {
namespace {

// An import's last_update_ns before its first sample: never received is stale, not fresh.
constexpr std::int64_t kNeverUpdated = std::numeric_limits<std::int64_t>::min();

using dds_detail::SampleStamp;
using dds_detail::WriterShape;
using Msg = std_msgs_msg_dds__Float64MultiArray_;
using Dim = std_msgs_msg_dds__MultiArrayDimension_;

std::int64_t monotonic_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
std::int64_t wall_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Deletes a DDS entity (and everything it made) when it goes.
struct Entity {
  dds_entity_t id = 0;
  Entity() = default;
  explicit Entity(dds_entity_t e) : id(e) {}
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  ~Entity() {
    if (id > 0) dds_delete(id);
  }
};

struct Qos {
  dds_qos_t* q = dds_create_qos();
  Qos() = default;
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  ~Qos() { dds_delete_qos(q); }
};

struct ExportPort {
  std::string variable;
  VarIndex index = 0;
  std::uint32_t count = 0;
  dds_entity_t writer = 0;
  dds_entity_t echo = 0;       // a reader of the same topic that ignores our own writer (eq. 1)
  std::uint64_t seen = 0;      // the table's version last published
  std::uint64_t sequence = 0;  // samples published
  std::vector<double> values;
};

// What an import's listener is given: the bridge and which of its imports.
struct ListenerArg {
  RemotePorts::Impl* impl;
  std::size_t index;
};

struct ImportPort {
  ImportSpec spec;
  VarIndex index = 0;
  dds_entity_t reader = 0;
  // Monotonic, ours; kNeverUpdated before the first sample. Relaxed everywhere: a time on its
  // own, written by DDS's listener thread and judged by the taker's.
  std::atomic<std::int64_t> last_update_ns{kNeverUpdated};
  std::set<dds_instance_handle_t> discovered;  // remote writers whose shape was checked (the taker's)
  bool said_stale = false;                     // the taker's: the last change reported was "stale"
  ImportStatus status;                         // guarded by Impl::status_mutex
};

// The writer's stamp, in whichever dimension's label carries it; none from a ROS 2 node.
std::optional<SampleStamp> stamp_of(const Msg& msg) {
  for (std::uint32_t i = 0; i < msg.layout.dim._length; ++i)
    if (const char* label = msg.layout.dim._buffer[i].label; label != nullptr)
      if (auto stamp = dds_detail::parse_stamp_label(label)) return stamp;
  return std::nullopt;
}

std::string dds_error(std::string_view what, dds_return_t rc) {
  return fmt::format("DDS: {}: {}", what, dds_strretcode(rc));
}

}  // namespace

struct RemotePorts::Impl {
  SubsystemSpec spec;
  RemotePortsOptions options;
  GlobalTable table;
  Entity participant;  // deleting it deletes every other entity it made
  std::vector<ExportPort> exports;
  std::deque<ImportPort> imports;
  dds_entity_t waitset = 0;
  dds_entity_t wake = 0;  // a guard condition that ends the taker's wait at shutdown
  // The builtin topic of every writer discovered, with imports: one of another type on an
  // import's topic is named (check_publication). Its attach id is the waitset's last.
  dds_entity_t publications = 0;

  std::atomic<bool> stopping{false};
  // What the publisher sleeps on: the producers' watch (options.exports_written) or its own; the
  // destructor ends the sleep through it.
  std::shared_ptr<WriteWatch> watch;
  std::thread publisher;
  std::thread taker;

  mutable std::mutex status_mutex;  // imports[i].status, errors, changes, reported
  std::vector<std::string> errors;
  std::vector<std::string> changes;  // an import's first sample, stale, fresh again
  std::set<std::string> reported;    // "variable|writer|count" of wrong-size writers already named
  std::vector<std::unique_ptr<ListenerArg>> listener_args;  // what each import's listener is given
  std::optional<IllegalConfigurationHold> stale_hold;       // the taker's thread only
  std::optional<IllegalConfigurationHold> conflict_hold;    // the taker's thread only

  explicit Impl(GlobalTable t) : table(std::move(t)) {}

  void publish_loop();
  void publish(ExportPort& port);
  void take_loop();
  void take(ImportPort& port);
  /// From now on each import's samples are taken on DDS's own receive thread, as they arrive:
  /// one thread hop fewer than a waitset's. Cyclone DDS calls one reader's listener at a time.
  Result<void> listen_to_imports();
  void take_sample(ImportPort& port, const Msg& msg, const dds_sample_info_t& info);
  Result<void> add_import(const ImportSpec& import, dds_entity_t subscriber, dds_entity_t topic);
  void check_echo(ExportPort& port);
  void check_discovered(ImportPort& port);
  void refuse_shape(ImportPort& port, const std::string& who, std::uint32_t length);
  void check_publications();
  void check_publication(const dds_builtintopic_endpoint_t& writer);
  void refuse(ImportPort& port, const std::string& key, std::string message);
  void judge_staleness();
  void report(const std::string& key, std::string message);
};

void RemotePorts::Impl::publish(ExportPort& port) {
  const ReadOutcome got = table.read(port.index, port.values.data(), port.seen);
  if (got.freshness != Freshness::kNew) return;
  port.seen = got.version;
  const std::int64_t now = wall_ns();
  const std::string stamp = dds_detail::stamp_label(SampleStamp{spec.name, ++port.sequence, now});
  // dim[0] is the ROS idiom for a vector of count values; dim[1] of size 1 carries the stamp.
  // The generated C struct's labels are char*; dds_write only reads them.
  std::array<Dim, 2> dims{Dim{const_cast<char*>(port.variable.c_str()), port.count,  // NOLINT(*-const-cast)
                              port.count},
                          Dim{const_cast<char*>(stamp.c_str()), 1, 1}};  // NOLINT(*-const-cast)
  Msg msg{};
  msg.layout.dim._length = msg.layout.dim._maximum = 2;
  msg.layout.dim._buffer = dims.data();
  msg.layout.data_offset = 0;
  msg.data._length = msg.data._maximum = port.count;
  msg.data._buffer = port.values.data();
  if (const dds_return_t rc = dds_write_ts(port.writer, &msg, now); rc < 0)
    report("write|" + port.variable, dds_error(fmt::format("export {}: write", port.variable), rc));
}

// Sleeps until a producer publishes an export (the watch), the destructor's word, or the poll's
// time, whichever comes first; then publishes every export whose version moved.
void RemotePorts::Impl::publish_loop() {
  while (!stopping.load(std::memory_order_relaxed)) {  // relaxed: the flag carries no data
    (void)watch->take();                               // before the reads: news after it wakes us again
    for (auto& port : exports) publish(port);
    watch->wait_until(monotonic_ns() + options.poll_ns);
  }
}

void RemotePorts::Impl::take(ImportPort& port) {
  std::array<void*, 1> samples{nullptr};
  std::array<dds_sample_info_t, 1> info{};
  while (true) {
    const dds_return_t n = dds_take(port.reader, samples.data(), info.data(), 1, 1);
    if (n <= 0) return;
    if (info[0].valid_data) take_sample(port, *static_cast<const Msg*>(samples[0]), info[0]);
    dds_return_loan(port.reader, samples.data(), n);
  }
}

Result<void> RemotePorts::Impl::listen_to_imports() {
  for (std::size_t i = 0; i < imports.size(); ++i) {
    listener_args.push_back(std::make_unique<ListenerArg>(ListenerArg{this, i}));
    dds_listener_t* listener = dds_create_listener(listener_args.back().get());
    dds_lset_data_available(listener, [](dds_entity_t /*reader*/, void* arg) {
      auto* a = static_cast<ListenerArg*>(arg);
      a->impl->take(a->impl->imports[a->index]);
    });
    const dds_return_t rc = dds_set_listener(imports[i].reader, listener);
    dds_delete_listener(listener);  // the reader keeps its own copy
    if (rc < 0)
      return make_error(Errc::kInvalidInput, dds_error(fmt::format("import {}", imports[i].spec.variable), rc));
    take(imports[i]);  // what came before the listener did
  }
  return {};
}

void RemotePorts::Impl::take_sample(ImportPort& port, const Msg& msg, const dds_sample_info_t& info) {
  const std::uint32_t offset = msg.layout.data_offset;
  const std::uint32_t length = msg.data._length >= offset ? msg.data._length - offset : 0;
  // The value first, its bookkeeping after: a reader of the table waits for nothing else.
  if (length == port.spec.count) {
    table.write(port.index, msg.data._buffer + offset);
    port.last_update_ns.store(monotonic_ns(), std::memory_order_relaxed);  // relaxed: see its declaration
  }
  std::optional<SampleStamp> stamp = stamp_of(msg);
  const auto who = [&] {
    return stamp ? fmt::format("subsystem {}", stamp->writer)
                 : std::string("a writer without a Chimera stamp (a ROS 2 node?)");
  };
  if (length != port.spec.count) {
    refuse_shape(port, stamp ? who() : fmt::format("{}, instance {:x}", who(), info.publication_handle), length);
    std::lock_guard guard(status_mutex);
    ++port.status.refused;
    return;
  }
  std::lock_guard guard(status_mutex);
  if (++port.status.samples == 1)
    changes.push_back(fmt::format("import {}: first sample, from {}", port.spec.variable, who()));
  port.status.writer = stamp ? std::move(stamp->writer) : std::string();
  port.status.writer_sequence = stamp ? stamp->sequence : 0;
  port.status.writer_time_ns = stamp ? stamp->time_ns : info.source_timestamp;
}

void RemotePorts::Impl::refuse_shape(ImportPort& port, const std::string& who, std::uint32_t length) {
  refuse(port, fmt::format("{}|{}|{}", port.spec.variable, who, length),
         fmt::format("import {}: subsystem {} reads f64[{}] but {} publishes f64[{}] on rt/{}; its samples are refused",
                     port.spec.variable, spec.name, port.spec.count, who, length, port.spec.variable));
}

// The shape check at discovery: a Chimera writer says its count in its USER_DATA, which arrives
// with the writer's discovery, so a mismatch is named before (and without) any sample. A writer
// without it (a ROS 2 node) is checked sample by sample, as every writer also is.
void RemotePorts::Impl::check_discovered(ImportPort& port) {
  dds_subscription_matched_status_t matched{};
  dds_get_subscription_matched_status(port.reader, &matched);  // resets the status that woke us
  std::vector<dds_instance_handle_t> writers(std::max<std::uint32_t>(matched.current_count, 1) + 8);
  const dds_return_t n = dds_get_matched_publications(port.reader, writers.data(), writers.size());
  for (dds_return_t i = 0; i < std::min<dds_return_t>(n, static_cast<dds_return_t>(writers.size())); ++i) {
    const dds_instance_handle_t handle = writers[static_cast<std::size_t>(i)];
    if (!port.discovered.insert(handle).second) continue;
    dds_builtintopic_endpoint_t* endpoint = dds_get_matched_publication_data(port.reader, handle);
    if (endpoint == nullptr) continue;
    void* data = nullptr;
    std::size_t size = 0;
    if (endpoint->qos != nullptr && dds_qget_userdata(endpoint->qos, &data, &size) && data != nullptr) {
      const auto shape = dds_detail::parse_shape_userdata(std::string_view(static_cast<const char*>(data), size));
      if (shape && shape->count != port.spec.count)
        refuse_shape(port, fmt::format("subsystem {}", shape->writer), shape->count);
      dds_free(data);
    }
    dds_builtintopic_free_endpoint(endpoint);
  }
}

// "std_msgs::msg::dds_::String_" as ROS 2 names it: "std_msgs/msg/String".
std::string ros_type_name(std::string_view dds_name) {
  std::string out;
  for (std::size_t i = 0; i < dds_name.size();) {
    if (dds_name.substr(i).starts_with("::dds_::")) {
      out += '/';
      i += 8;
    } else if (dds_name.substr(i).starts_with("::")) {
      out += '/';
      i += 2;
    } else {
      out += dds_name[i++];
    }
  }
  if (out.ends_with('_')) out.pop_back();
  return out;
}

// Whether a writer with QoS `qos` publishes in `partition` ("": DDS's default one).
bool in_partition(const dds_qos_t* qos, const std::string& partition) {
  std::uint32_t n = 0;
  char** names = nullptr;
  if (qos == nullptr || !dds_qget_partition(qos, &n, &names) || n == 0) {
    if (names != nullptr) dds_free(static_cast<void*>(names));
    return partition.empty();
  }
  bool found = false;
  for (std::uint32_t i = 0; i < n; ++i) {
    found = found || partition == names[i];
    dds_free(names[i]);
  }
  dds_free(static_cast<void*>(names));
  return found;
}

// Every writer discovered, as it is: one on an import's topic of another type is named.
void RemotePorts::Impl::check_publications() {
  constexpr std::size_t kBatch = 16;
  std::array<void*, kBatch> samples{};
  std::array<dds_sample_info_t, kBatch> info{};
  while (true) {
    samples.fill(nullptr);
    const dds_return_t n = dds_take(publications, samples.data(), info.data(), kBatch, kBatch);
    if (n <= 0) return;
    for (dds_return_t i = 0; i < n; ++i)
      if (info[static_cast<std::size_t>(i)].valid_data)
        check_publication(*static_cast<const dds_builtintopic_endpoint_t*>(samples[static_cast<std::size_t>(i)]));
    dds_return_loan(publications, samples.data(), n);
  }
}

// Equation 2's type across machines. DDS matches a reader only with writers of its type name, so a
// writer of another type on an import's topic is never heard from: without this its variable
// would simply stay stale, with nothing to say why.
void RemotePorts::Impl::check_publication(const dds_builtintopic_endpoint_t& writer) {
  const std::string_view topic = writer.topic_name != nullptr ? writer.topic_name : "";
  const std::string_view type = writer.type_name != nullptr ? writer.type_name : "";
  if (!topic.starts_with("rt/") || type == std_msgs_msg_dds__Float64MultiArray__desc.m_typename) return;
  const std::string_view variable = topic.substr(3);
  auto port =
      std::find_if(imports.begin(), imports.end(), [&](const ImportPort& p) { return p.spec.variable == variable; });
  if (port == imports.end() || !in_partition(writer.qos, spec.dds.partition)) return;
  std::string who = "a writer without a Chimera stamp (a ROS 2 node?)";
  void* data = nullptr;
  std::size_t size = 0;
  if (writer.qos != nullptr && dds_qget_userdata(writer.qos, &data, &size) && data != nullptr) {
    if (const auto shape = dds_detail::parse_shape_userdata(std::string_view(static_cast<const char*>(data), size)))
      who = fmt::format("subsystem {}", shape->writer);
    dds_free(data);
  }
  const auto& guid = writer.key.v;
  refuse(*port, fmt::format("type|{}|{}|{:02x}", variable, type, fmt::join(guid, "")),
         fmt::format("import {}: subsystem {} reads {} but {} publishes {} on rt/{}; DDS delivers none of its samples",
                     variable, spec.name, ros_type_name(std_msgs_msg_dds__Float64MultiArray__desc.m_typename), who,
                     ros_type_name(type), variable));
}

// Eq. (1) across machines: any sample on an export's topic that is not ours comes from a second
// producer. Both subsystems see the other's samples, so both refuse: the flag stays raised for
// the rest of the run, since which value an importer holds is then anyone's guess.
void RemotePorts::Impl::check_echo(ExportPort& port) {
  std::array<void*, 1> samples{nullptr};
  std::array<dds_sample_info_t, 1> info{};
  while (true) {
    const dds_return_t n = dds_take(port.echo, samples.data(), info.data(), 1, 1);
    if (n <= 0) return;
    if (info[0].valid_data) {
      const auto* msg = static_cast<const Msg*>(samples[0]);
      const std::optional<SampleStamp> stamp = stamp_of(*msg);
      const std::string who = stamp ? fmt::format("subsystem {}", stamp->writer)
                                    : std::string("a writer without a Chimera stamp (a ROS 2 node?)");
      report(fmt::format("rule1|{}|{}", port.variable, who),
             fmt::format("rule 1: {} is exported by subsystem {} and by {} on rt/{}; the illegal-configuration "
                         "flag stays raised",
                         port.variable, spec.name, who, port.variable));
      if (!conflict_hold) conflict_hold.emplace(table);
    }
    dds_return_loan(port.echo, samples.data(), n);
  }
}

void RemotePorts::Impl::judge_staleness() {
  const std::int64_t now = monotonic_ns();
  bool any_stale = false;
  {
    std::lock_guard guard(status_mutex);
    for (auto& port : imports) {
      const std::int64_t last = port.last_update_ns.load(std::memory_order_relaxed);  // relaxed: as declared
      const bool never = last == kNeverUpdated;
      port.status.stale = never || now - last > port.spec.max_age_ns;
      any_stale = any_stale || port.status.stale;
      if (port.status.stale == port.said_stale) continue;
      port.said_stale = port.status.stale;
      changes.push_back(port.status.stale
                            ? fmt::format("import {}: stale, {}{}", port.spec.variable,
                                          never
                                              ? std::string("no sample yet")
                                              : fmt::format("no sample for {} (max_age)", format_duration(now - last)),
                                          options.hold_when_stale ? ": the illegal-configuration flag is raised" : "")
                            : fmt::format("import {}: fresh again, from {}", port.spec.variable,
                                          port.status.writer.empty() ? std::string("a writer without a Chimera stamp")
                                                                     : "subsystem " + port.status.writer));
    }
    // Under the status lock: no one reads "stale" before the flag it says is raised is up.
    if (!options.hold_when_stale) return;
    if (any_stale && !stale_hold) stale_hold.emplace(table);
    if (!any_stale) stale_hold.reset();
  }
}

void RemotePorts::Impl::take_loop() {
  // Wake at least this often to judge staleness; a tenth of the tightest max_age bounds how late.
  std::int64_t tick = options.poll_ns * 10;
  for (const auto& port : imports) tick = std::min(tick, std::max<std::int64_t>(port.spec.max_age_ns / 10, 100'000));
  const std::size_t first_discovery = imports.size() + 1 + exports.size();
  const std::size_t publications_id = first_discovery + imports.size();
  std::vector<dds_attach_t> triggered(publications_id + 1);
  while (!stopping.load(std::memory_order_relaxed)) {  // relaxed: the flag carries no data
    const dds_return_t n =
        dds_waitset_wait(waitset, triggered.data(), triggered.size(), static_cast<dds_duration_t>(tick));
    for (dds_return_t i = 0; i < n; ++i) {
      const auto which = static_cast<std::size_t>(triggered[static_cast<std::size_t>(i)]);
      if (which > imports.size() && which < first_discovery) check_echo(exports[which - imports.size() - 1]);
      if (which >= first_discovery && which - first_discovery < imports.size())
        check_discovered(imports[which - first_discovery]);
      if (which == publications_id) check_publications();
    }
    judge_staleness();
  }
  stale_hold.reset();
  conflict_hold.reset();
}

void RemotePorts::Impl::report(const std::string& key, std::string message) {
  std::lock_guard guard(status_mutex);
  if (reported.insert(key).second) errors.push_back(std::move(message));
}

void RemotePorts::Impl::refuse(ImportPort& port, const std::string& key, std::string message) {
  std::lock_guard guard(status_mutex);
  port.status.refusal = message;
  if (reported.insert(key).second) errors.push_back(std::move(message));
}

RemotePorts::RemotePorts(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

RemotePorts::~RemotePorts() {
  impl_->stopping.store(true, std::memory_order_relaxed);  // relaxed: the joins below order the rest
  if (impl_->watch) impl_->watch->written();               // stays taken until the publisher looks: it cannot miss it
  if (impl_->wake > 0) dds_set_guardcondition(impl_->wake, true);
  if (impl_->publisher.joinable()) impl_->publisher.join();
  if (impl_->taker.joinable()) impl_->taker.join();
  // The participant first (it waits for a listener still running), then the ports it writes to.
  if (impl_->participant.id > 0) dds_delete(impl_->participant.id);
  impl_->participant.id = 0;
}

namespace {

Result<void> check_shape(const GlobalTable& table, const std::string& variable, std::uint32_t count,
                         std::string_view role, VarIndex& index) {
  const auto found = table.find(variable);
  if (!found)
    return make_error(Errc::kInvalidInput,
                      fmt::format("{} {}: not a variable of table {}", role, variable, table.shm_name()));
  const VarShape shape = table.shape(*found);
  if (shape.type != ElemType::kF64 || (count != 0 && shape.count != count))
    return make_error(Errc::kInvalidInput, fmt::format("{} {}: the table holds it as {}[{}], not f64[{}]", role,
                                                       variable, elem_name(shape.type), shape.count, count));
  index = *found;
  return {};
}

}  // namespace

// One import's reader on `topic`, attached to the taker's waitset for its data and its discovered
// writers.
Result<void> RemotePorts::Impl::add_import(const ImportSpec& import, dds_entity_t subscriber, dds_entity_t topic) {
  ImportPort& port = imports.emplace_back();  // in place: a deque never moves it, and a listener holds it
  port.spec = import;
  port.status.variable = import.variable;
  port.status.max_age_ns = import.max_age_ns;
  if (auto ok = check_shape(table, import.variable, import.count, "import", port.index); !ok) return ok;
  Qos qos;
  dds_qset_history(qos.q, DDS_HISTORY_KEEP_LAST, 1);
  dds_qset_reliability(
      qos.q, import.reliability == DdsReliability::kReliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
      DDS_MSECS(100));
  dds_qset_durability(qos.q, import.durability == DdsDurability::kTransientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL
                                                                                 : DDS_DURABILITY_VOLATILE);
  port.reader = topic < 0 ? topic : dds_create_reader(subscriber, topic, qos.q, nullptr);
  if (port.reader < 0)
    return make_error(Errc::kInvalidInput, dds_error(fmt::format("import {}", import.variable), port.reader));
  // The reader itself, woken only when a writer is matched or lost: its shape is checked then.
  // Its samples are taken by a listener (listen_to_imports), not through the waitset.
  const dds_return_t mask = dds_set_status_mask(port.reader, DDS_SUBSCRIPTION_MATCHED_STATUS);
  if (mask < 0 || dds_waitset_attach(waitset, port.reader,
                                     static_cast<dds_attach_t>(spec.imports.size() + 1 + spec.exports.size() +
                                                               imports.size() - 1)) < 0)
    return make_error(Errc::kInvalidInput, dds_error(fmt::format("import {}: discovery", import.variable), mask));
  return {};
}

Result<std::unique_ptr<RemotePorts>> RemotePorts::create(const SubsystemSpec& spec, std::string_view table_name,
                                                         RemotePortsOptions options) {
  auto table = GlobalTable::attach(table_name);
  if (!table) return table.error();
  auto impl = std::make_unique<Impl>(std::move(*table));
  impl->spec = spec;
  impl->options = std::move(options);
  Impl& m = *impl;

  m.participant.id = dds_create_participant(static_cast<dds_domainid_t>(spec.dds.domain), nullptr, nullptr);
  if (m.participant.id < 0)
    return make_error(Errc::kInvalidInput, dds_error(fmt::format("domain {}", spec.dds.domain), m.participant.id));
  Qos group;
  if (!spec.dds.partition.empty()) dds_qset_partition1(group.q, spec.dds.partition.c_str());
  const dds_entity_t publisher = dds_create_publisher(m.participant.id, group.q, nullptr);
  const dds_entity_t subscriber = dds_create_subscriber(m.participant.id, group.q, nullptr);
  if (publisher < 0 || subscriber < 0)
    return make_error(Errc::kInvalidInput, dds_error("publisher and subscriber", std::min(publisher, subscriber)));
  // Attached to the waitset as: (i unused: import i's data goes to a listener), the wake-up -> imports.size(), export
  // k's echo -> imports.size() + 1 + k, import i's discovered writers -> imports.size() + 1 + exports.size() + i.
  m.waitset = dds_create_waitset(m.participant.id);
  m.wake = dds_create_guardcondition(m.participant.id);
  if (m.waitset < 0 || m.wake < 0 ||
      dds_waitset_attach(m.waitset, m.wake, static_cast<dds_attach_t>(spec.imports.size())) < 0)
    return make_error(Errc::kInvalidInput, dds_error("waitset", std::min(m.waitset, m.wake)));
  auto topic = [&](const std::string& variable) {
    return dds_create_topic(m.participant.id, &std_msgs_msg_dds__Float64MultiArray__desc, ("rt/" + variable).c_str(),
                            nullptr, nullptr);
  };

  for (const auto& x : spec.exports) {
    ExportPort port;
    port.variable = x.variable;
    if (auto ok = check_shape(m.table, x.variable, 0, "export", port.index); !ok) return ok.error();
    port.count = m.table.shape(port.index).count;
    port.values.resize(port.count);
    const dds_entity_t t = topic(x.variable);
    // The strongest offer matches every reader: reliable, and the last value kept for late joiners.
    Qos qos;
    dds_qset_history(qos.q, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_reliability(qos.q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_durability(qos.q, DDS_DURABILITY_TRANSIENT_LOCAL);
    // Its shape, for every importer to check at discovery (check_discovered).
    const std::string shape = dds_detail::shape_userdata(WriterShape{spec.name, port.count});
    dds_qset_userdata(qos.q, shape.data(), shape.size());
    port.writer = t < 0 ? t : dds_create_writer(publisher, t, qos.q, nullptr);
    // The echo hears every other writer of the topic in the partition, never this participant's.
    Qos echo_qos;
    dds_qset_history(echo_qos.q, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_reliability(echo_qos.q, DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_ignorelocal(echo_qos.q, DDS_IGNORELOCAL_PARTICIPANT);
    port.echo = port.writer < 0 ? port.writer : dds_create_reader(subscriber, t, echo_qos.q, nullptr);
    const dds_entity_t heard = port.echo < 0 ? port.echo : dds_create_readcondition(port.echo, DDS_ANY_STATE);
    if (heard < 0 ||
        dds_waitset_attach(m.waitset, heard, static_cast<dds_attach_t>(spec.imports.size() + 1 + m.exports.size())) < 0)
      return make_error(Errc::kInvalidInput, dds_error(fmt::format("export {}", x.variable), heard));
    m.exports.push_back(std::move(port));
  }
  for (const auto& i : spec.imports)
    if (auto added = m.add_import(i, subscriber, topic(i.variable)); !added) return added.error();
  if (!m.imports.empty()) {
    m.publications = dds_create_reader(m.participant.id, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
    const dds_entity_t discovered =
        m.publications < 0 ? m.publications : dds_create_readcondition(m.publications, DDS_ANY_STATE);
    if (discovered < 0 ||
        dds_waitset_attach(m.waitset, discovered,
                           static_cast<dds_attach_t>(2 * spec.imports.size() + 1 + spec.exports.size())) < 0)
      return make_error(Errc::kInvalidInput, dds_error("the writers' discovery", discovered));
  }
  // Never received is stale: judged now, before any thread, so the flag is up (with
  // hold_when_stale) before the caller lets a task read an import that has no value yet.
  m.judge_staleness();

  m.watch = m.options.exports_written ? m.options.exports_written : std::make_shared<WriteWatch>();
  if (!m.exports.empty()) m.publisher = std::thread([&m] { m.publish_loop(); });
  m.taker = std::thread([&m] { m.take_loop(); });  // also the exports' echoes
  // Last: nothing below may fail, since the listeners run from here on until the participant goes.
  if (auto listening = m.listen_to_imports(); !listening) {
    RemotePorts stopped(std::move(impl));  // its destructor stops both threads
    return listening.error();
  }
  return std::unique_ptr<RemotePorts>(new RemotePorts(std::move(impl)));
}

std::vector<ImportStatus> RemotePorts::imports() const {
  const std::int64_t now = monotonic_ns();
  std::lock_guard guard(impl_->status_mutex);
  std::vector<ImportStatus> out;
  out.reserve(impl_->imports.size());
  for (const auto& port : impl_->imports) {
    out.push_back(port.status);
    const std::int64_t last = port.last_update_ns.load(std::memory_order_relaxed);  // relaxed: as declared
    out.back().age_ns = last == kNeverUpdated ? -1 : std::max<std::int64_t>(now - last, 0);
  }
  return out;
}

std::vector<std::string> RemotePorts::take_errors() {
  std::lock_guard guard(impl_->status_mutex);
  return std::exchange(impl_->errors, {});
}

std::vector<std::string> RemotePorts::take_changes() {
  std::lock_guard guard(impl_->status_mutex);
  return std::exchange(impl_->changes, {});
}

}  // namespace chimera
