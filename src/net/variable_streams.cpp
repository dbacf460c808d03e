#include "chimera/net/variable_streams.hpp"

#include <civetweb.h>

#include <chrono>
#include <cmath>
#include <system_error>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace chimera::net {

namespace {

using nlohmann::json;

std::string dump(const json& doc) { return doc.dump(-1, ' ', false, json::error_handler_t::replace); }

std::string error_text(std::string_view code, std::string_view message) {
  return dump(json{{"ok", false}, {"error", {{"code", code}, {"message", message}}}});
}

}  // namespace

VariableStream::VariableStream(ControlGate& gate, mg_connection* conn) : gate_(gate), conn_(conn) {
  constexpr std::size_t kStackBytes = std::size_t{256} << 10;  // a sample's JSON needs a few KiB
  pthread_attr_t attributes;
  pthread_attr_init(&attributes);
  pthread_attr_setstacksize(&attributes, kStackBytes);
  const int failed = pthread_create(
      &thread_, &attributes,
      [](void* self) -> void* {
        static_cast<VariableStream*>(self)->run();
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

VariableStream::~VariableStream() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (started_) pthread_join(thread_, nullptr);
}

void VariableStream::receive(std::string_view text) {
  const json doc = json::parse(text, nullptr, false);
  std::string reply;
  std::vector<std::string> variables;
  double rate = 0;
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("variables") || !doc["variables"].is_array() ||
      !doc.contains("rate_hz") || !doc["rate_hz"].is_number()) {
    reply = error_text("bad_request", R"(a subscription is {"variables": ["theta_m", ...], "rate_hz": 100})");
  } else {
    rate = doc["rate_hz"].get<double>();
    for (const auto& v : doc["variables"])
      if (v.is_string()) variables.push_back(v.get<std::string>());
    if (variables.size() != doc["variables"].size() || variables.size() > kMaxVariables)
      reply = error_text("bad_request", fmt::format("variables: at most {} names", kMaxVariables));
    else if (!(rate >= kMinRateHz && rate <= kMaxRateHz))
      reply = error_text("bad_request", fmt::format("rate_hz: from {} to {}", kMinRateHz, kMaxRateHz));
    for (const auto& v : variables) {
      if (!reply.empty()) break;
      auto value = gate_.sample(v);
      if (!value && value.error().code == Errc::kNotFound && value.error().message.starts_with("no state variable"))
        reply = error_text("not_found", value.error().message);
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (reply.empty()) {
      variables_ = variables;
      period_ns_ = std::llround(1e9 / rate);
      reply = dump(json{{"ok", true}, {"variables", variables}, {"rate_hz", rate}});
    }
    pending_reply_ = std::move(reply);  // only the latest: a client that floods us gets one reply
  }
  changed_.notify_all();
}

std::string VariableStream::sample(const std::vector<std::string>& variables, std::uint64_t seq,
                                   std::int64_t t_ns) const {
  json values = json::object();
  for (const auto& v : variables) {
    auto value = gate_.sample(v);
    values[v] = value ? json(*value) : json(nullptr);  // not written yet: null
  }
  return dump(json{{"seq", seq}, {"t_ns", t_ns}, {"values", std::move(values)}});
}

bool VariableStream::send(const std::string& text) {
  // civetweb writes to the connection too (pongs, the close frame): one writer at a time.
  mg_lock_connection(conn_);
  const int sent = mg_websocket_write(conn_, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size());
  mg_unlock_connection(conn_);
  return sent > 0;
}

void VariableStream::run() {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto next = start;
  std::uint64_t seq = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    if (period_ns_ == 0 && pending_reply_.empty()) {
      changed_.wait(lock);
      next = Clock::now();
      continue;
    }
    if (!pending_reply_.empty()) {
      std::string reply = std::move(pending_reply_);
      pending_reply_.clear();
      lock.unlock();
      const bool ok = send(reply);
      lock.lock();
      if (!ok) return;
      next = Clock::now();
      continue;
    }
    if (changed_.wait_until(lock, next, [this] { return stopping_ || !pending_reply_.empty(); })) continue;
    const std::vector<std::string> variables = variables_;
    const auto period = std::chrono::nanoseconds(period_ns_);
    lock.unlock();
    const std::string frame =
        sample(variables, seq++, std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start).count());
    const bool ok = send(frame);  // blocks only this thread when the client reads slowly
    lock.lock();
    if (!ok) return;
    // The next sample on the rate's grid: a client that took longer, or a thread woken late,
    // skips the grid points it missed rather than sending them in a burst, so two samples are
    // never closer than the grid allows after the first.
    next += period;
    if (const auto now = Clock::now(); next < now) next += period * ((now - next) / period + 1);
  }
}

}  // namespace chimera::net
