#include "chimera/net/api_stream.hpp"

#include <civetweb.h>

#include <algorithm>
#include <chrono>
#include <initializer_list>
#include <iterator>
#include <optional>
#include <system_error>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "chimera/control/stats_json.hpp"
#include "sample_text.hpp"

namespace chimera::net {

namespace {

using nlohmann::json;

std::string dump(const json& doc) { return doc.dump(-1, ' ', false, json::error_handler_t::replace); }

std::string error_text(std::string_view code, std::string_view message) {
  return dump(json{{"ok", false}, {"error", {{"code", code}, {"message", message}}}});
}

constexpr std::string_view kUsage =
    R"(a subscription is {"variables": ["theta_m", ...], "rate_hz": 100, "batch_hz": 30, "timing_hz": 2, )"
    R"("tasks": [...], "events": true}, each part optional, at least one asked for)";

struct Refusal {
  std::string code;
  std::string message;
};

std::optional<std::vector<std::string>> names_of(const json& doc, std::string_view key) {
  if (!doc.contains(key)) return std::vector<std::string>{};
  const json& list = doc[key];
  if (!list.is_array()) return std::nullopt;
  std::vector<std::string> names;
  for (const auto& v : list) {
    if (!v.is_string()) return std::nullopt;
    names.push_back(v.get<std::string>());
  }
  return names;
}

std::optional<double> rate_of(const json& doc, std::string_view key) {
  if (!doc.contains(key) || !doc[key].is_number()) return std::nullopt;
  return doc[key].get<double>();
}

// A variable or task of `wanted` that the subsystem does not have.
std::optional<Refusal> unknown_name(const Subscription& wanted, const ControlGate& gate) {
  for (const auto& v : wanted.variables) {
    auto value = gate.sample(v);
    if (!value && value.error().code == Errc::kNotFound && value.error().message.starts_with("no state variable"))
      return Refusal{"not_found", value.error().message};
  }
  if (wanted.timing_tasks.empty()) return std::nullopt;
  const auto states = gate.states();
  for (const auto& t : wanted.timing_tasks)
    if (std::none_of(states.begin(), states.end(), [&](const auto& s) { return s.first == t; }))
      return Refusal{"not_found", fmt::format("no task named '{}'", t)};
  return std::nullopt;
}

// The subscription a client's text asks for, or why it cannot be had: checked whole, so that a
// refused one leaves the stream as it was.
std::variant<Subscription, Refusal> parse_subscription(std::string_view text, ControlGate& gate) {
  const json doc = json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) return Refusal{"bad_request", std::string(kUsage)};
  for (const auto& [key, value] : doc.items())
    if (key != "variables" && key != "rate_hz" && key != "batch_hz" && key != "timing_hz" && key != "tasks" &&
        key != "events")
      return Refusal{"bad_request", fmt::format("unknown key '{}': {}", key, kUsage)};
  Subscription wanted;
  const auto variables = names_of(doc, "variables");
  const auto tasks = names_of(doc, "tasks");
  if (!variables || !tasks) return Refusal{"bad_request", "variables and tasks are lists of names"};
  if (variables->size() > ApiStream::kMaxVariables)
    return Refusal{"bad_request", fmt::format("variables: at most {} names", ApiStream::kMaxVariables)};
  wanted.variables = *variables;
  wanted.timing_tasks = *tasks;
  if (doc.contains("rate_hz") || !wanted.variables.empty()) {
    const auto rate = rate_of(doc, "rate_hz");
    if (!rate || !(*rate >= ApiStream::kMinRateHz && *rate <= ApiStream::kMaxRateHz))
      return Refusal{"bad_request", fmt::format("rate_hz: from {} to {}, with variables", ApiStream::kMinRateHz,
                                                ApiStream::kMaxRateHz)};
    if (wanted.variables.empty()) return Refusal{"bad_request", "rate_hz without variables to sample"};
    wanted.sample_period_ns = std::llround(1e9 / *rate);
  }
  if (wanted.sample_period_ns > 0) {
    // Up to the writers' rate: asked faster, a stream would send each value several times (the
    // ack says the rate it sends at).
    const std::int64_t writers = gate.fastest_writer_period_ns(wanted.variables);
    wanted.sample_period_ns = std::max(wanted.sample_period_ns, writers);
  }
  if (doc.contains("batch_hz")) {
    const auto batch = rate_of(doc, "batch_hz");
    if (wanted.sample_period_ns == 0) return Refusal{"bad_request", "batch_hz without variables to sample"};
    if (!batch || !(*batch >= ApiStream::kMinRateHz && *batch <= ApiStream::kMaxRateHz))
      return Refusal{"bad_request", fmt::format("batch_hz: from {} to {}, frames a second", ApiStream::kMinRateHz,
                                                ApiStream::kMaxRateHz)};
    // As often as the samples, or more: one frame per sample, as without it.
    const std::int64_t period = std::llround(1e9 / *batch);
    if (period > wanted.sample_period_ns) wanted.batch_period_ns = period;
  }
  if (doc.contains("timing_hz")) {
    const auto rate = rate_of(doc, "timing_hz");
    if (!rate || !(*rate >= ApiStream::kMinRateHz && *rate <= ApiStream::kMaxTimingHz))
      return Refusal{"bad_request",
                     fmt::format("timing_hz: from {} to {}", ApiStream::kMinRateHz, ApiStream::kMaxTimingHz)};
    wanted.timing_period_ns = std::llround(1e9 / *rate);
  } else if (!wanted.timing_tasks.empty()) {
    return Refusal{"bad_request", "tasks: the tasks whose timing to send, with timing_hz"};
  }
  if (doc.contains("events")) {
    if (!doc["events"].is_boolean()) return Refusal{"bad_request", "events: true or false"};
    wanted.events = doc["events"].get<bool>();
  }
  if (wanted.sample_period_ns == 0 && wanted.timing_period_ns == 0 && !wanted.events)
    return Refusal{"bad_request", std::string(kUsage)};
  if (auto unknown = unknown_name(wanted, gate)) return *unknown;
  return wanted;
}

using Clock = std::chrono::steady_clock;

// One deadline per part of a subscription; each stays on its own grid. A thread woken late (or a
// client that took longer) skips the grid points it missed by the time it woke, rather than
// getting them in a burst; the time it then spends on the frame does not count as missed (a
// batch of 1 kHz samples takes a while to format: judged after it, a sample in 30 was lost).
struct Part {
  std::int64_t period_ns = 0;  // 0: not asked for
  Clock::time_point next;
  std::uint64_t seq = 0;
  [[nodiscard]] bool due(Clock::time_point now) const { return period_ns > 0 && next <= now; }
  void advance(Clock::time_point now) {
    const std::chrono::nanoseconds period(period_ns);
    next += period;
    if (next < now) next += period * ((now - next) / period + 1);
  }
};

// When the first of the parts asked for is due; max() when none is.
Clock::time_point earliest(std::initializer_list<const Part*> parts) {
  Clock::time_point wake = Clock::time_point::max();
  for (const Part* part : parts)
    if (part->period_ns > 0) wake = std::min(wake, part->next);
  return wake;
}

double hz(std::int64_t period_ns) { return period_ns == 0 ? 0.0 : 1e9 / static_cast<double>(period_ns); }

}  // namespace

ApiStream::ApiStream(ControlGate& gate, mg_connection* conn) : gate_(gate), conn_(conn) {
  constexpr std::size_t kStackBytes = std::size_t{256} << 10;  // a sample's JSON needs a few KiB
  pthread_attr_t attributes;
  pthread_attr_init(&attributes);
  pthread_attr_setstacksize(&attributes, kStackBytes);
  const int failed = pthread_create(
      &thread_, &attributes,
      [](void* self) -> void* {
        static_cast<ApiStream*>(self)->run();
        return nullptr;
      },
      this);
  pthread_attr_destroy(&attributes);
  started_ = failed == 0;
  // Without its thread the stream could send nothing: the client is told why, as the log is, and
  // the stream is closed (the server's close callback then frees it as any other).
  if (!started_) {
    failure_ = fmt::format("no thread for this stream: {}", std::generic_category().message(failed));
    (void)send(error_text("unavailable", failure_));
    mg_lock_connection(conn_);
    (void)mg_websocket_write(conn_, MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE, nullptr, 0);
    mg_unlock_connection(conn_);
  }
}

ApiStream::~ApiStream() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (started_) pthread_join(thread_, nullptr);
}

void ApiStream::receive(std::string_view text) {
  auto parsed = parse_subscription(text, gate_);
  std::lock_guard<std::mutex> lock(mutex_);
  if (auto* refused = std::get_if<Refusal>(&parsed)) {
    pending_reply_ = error_text(refused->code, refused->message);  // only the latest: a flood gets one reply
  } else {
    wanted_ = std::move(std::get<Subscription>(parsed));
    ++generation_;
    json ack{{"ok", true},
             {"variables", wanted_.variables},
             {"rate_hz", hz(wanted_.sample_period_ns)},
             {"batch_hz", hz(wanted_.batch_period_ns)},
             {"timing_hz", hz(wanted_.timing_period_ns)},
             {"tasks", wanted_.timing_tasks},
             {"events", wanted_.events}};
    pending_reply_ = dump(ack);
  }
  changed_.notify_all();
}

std::string ApiStream::sample(const std::vector<std::string>& variables, std::uint64_t seq, std::int64_t t_ns) const {
  json values = json::object();
  for (const auto& v : variables) {
    auto value = gate_.sample(v);
    values[v] = value ? json(*value) : json(nullptr);  // not written yet: null
  }
  return dump(json{{"kind", "sample"}, {"seq", seq}, {"t_ns", t_ns}, {"values", std::move(values)}});
}

void ApiStream::add_to_batch(Batch& batch, const std::vector<std::string>& variables, std::uint64_t seq,
                             std::int64_t t_ns) const {
  if (batch.count == 0) {
    batch.first_seq = seq;
    batch.t_ns.clear();
    batch.values.resize(variables.size());
    for (auto& v : batch.values) v.clear();
  }
  const char* comma = batch.count == 0 ? "" : ",";
  fmt::format_to(std::back_inserter(batch.t_ns), "{}{}", comma, t_ns);
  for (std::size_t i = 0; i < variables.size(); ++i) {
    batch.values[i] += comma;
    append_sample_value(batch.values[i], gate_.sample(variables[i]));
  }
  ++batch.count;
}

std::string ApiStream::take_batch(Batch& batch, const std::vector<std::string>& variables) {
  std::string text = fmt::format(R"({{"kind": "samples", "seq": {}, "count": {}, "t_ns": [{}], "values": {{)",
                                 batch.first_seq, batch.count, batch.t_ns);
  for (std::size_t i = 0; i < variables.size() && i < batch.values.size(); ++i)
    fmt::format_to(std::back_inserter(text), "{}{}: [{}]", i == 0 ? "" : ", ", json(variables[i]).dump(),
                   batch.values[i]);
  text += "}}";
  batch.count = 0;
  return text;
}

std::string ApiStream::timing(const std::vector<std::string>& tasks, std::uint64_t seq, std::int64_t t_ns) const {
  std::vector<TaskSnapshot> all = gate_.snapshot();
  if (!tasks.empty())
    std::erase_if(all,
                  [&](const TaskSnapshot& t) { return std::find(tasks.begin(), tasks.end(), t.name) == tasks.end(); });
  // The figures of the `stats` command and --stats-json, as they are: one schema for all three.
  return fmt::format(R"({{"kind": "timing", "seq": {}, "t_ns": {}, "stats": {}}})", seq, t_ns,
                     stats_json(all, gate_.clock(), gate_.feed().switches(), false, JsonLayout::kCompact));
}

bool ApiStream::send_events(std::uint64_t& cursor) {
  constexpr std::size_t kBatch = 64;  // a burst of a thousand state changes goes out in pieces
  std::vector<EventFeed::Item> items;
  for (;;) {
    const std::uint64_t missed = gate_.feed().since(cursor, kBatch, items);
    if (missed > 0 && !send(dump(json{{"kind", "missed"}, {"events", missed}}))) return false;
    cursor += missed;
    for (const auto& item : items) {
      if (!send(fmt::format(R"({{"kind": "event", "seq": {}, "event": {}}})", item.seq, item.json))) return false;
      cursor = item.seq + 1;
    }
    if (items.size() < kBatch) return true;
  }
}

bool ApiStream::send(const std::string& text) {
  // civetweb writes to the connection too (pongs, the close frame): one writer at a time.
  mg_lock_connection(conn_);
  const int sent = mg_websocket_write(conn_, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size());
  mg_unlock_connection(conn_);
  return sent > 0;
}

void ApiStream::run() {
  using std::chrono::nanoseconds;
  Part samples;
  Part batches;
  Batch batch;
  Part timings;
  Part events;
  std::uint64_t cursor = 0;
  std::uint64_t generation = 0;
  auto start = Clock::now();
  Subscription wanted;
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    if (!pending_reply_.empty()) {
      std::string reply = std::move(pending_reply_);
      pending_reply_.clear();
      if (generation != generation_) {  // a new subscription: its parts start now
        generation = generation_;
        wanted = wanted_;
        start = Clock::now();
        samples = Part{wanted.sample_period_ns, start, 0};
        batches = Part{wanted.batch_period_ns, start + nanoseconds(wanted.batch_period_ns), 0};
        batch.count = 0;  // the last subscription's samples go with it
        timings = Part{wanted.timing_period_ns, start, 0};
        events = Part{wanted.events ? kEventPollNs : 0, start, 0};
        cursor = gate_.feed().next_seq();  // what happens from now on
      }
      lock.unlock();
      const bool ok = send(reply);
      lock.lock();
      if (!ok) return;
      continue;
    }
    const Clock::time_point wake = earliest({&samples, &batches, &timings, &events});
    if (wake == Clock::time_point::max()) {
      changed_.wait(lock);
      continue;
    }
    if (changed_.wait_until(lock, wake, [this] { return stopping_ || !pending_reply_.empty(); })) continue;
    lock.unlock();
    const auto now = Clock::now();
    const std::int64_t t_ns = std::chrono::duration_cast<nanoseconds>(now - start).count();
    bool ok = true;
    if (samples.due(now)) {
      if (wanted.batch_period_ns == 0) {
        // Blocks only this thread when the client reads slowly.
        ok = send(sample(wanted.variables, samples.seq++, t_ns));
      } else {
        add_to_batch(batch, wanted.variables, samples.seq++, t_ns);
        if (batch.count >= kMaxBatchSamples) ok = send(take_batch(batch, wanted.variables));
      }
      samples.advance(now);  // the grid points missed by the wake, not by the frame's work
    }
    if (ok && batches.due(now)) {
      if (batch.count > 0) ok = send(take_batch(batch, wanted.variables));
      batches.advance(Clock::now());
    }
    if (ok && timings.due(now)) {
      ok = send(timing(wanted.timing_tasks, timings.seq++, t_ns));
      timings.advance(Clock::now());
    }
    if (ok && events.due(now)) {
      ok = send_events(cursor);
      events.advance(Clock::now());
    }
    lock.lock();
    if (!ok) return;
  }
}

}  // namespace chimera::net
