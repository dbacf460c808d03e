// WebSocket streams from a real `chimera run --listen` (real clock): state variables at the
// client's rate, the tasks' timing, what happens (state changes, switches, events), tokens, bad
// subscriptions, and a stalled client that slows nobody.

#include <civetweb.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "chimera_process.hpp"
#include "http_client.hpp"
#include "run_chimera.hpp"
#include "support/json_text.hpp"

namespace chimera::test {
namespace {

using nlohmann::json;

const std::string kOperator = "operator-token-0123456789abcdef";
const std::string kViewer = "viewer-token-0123456789abcdef";

// What one WebSocket client received, filled by civetweb's client thread.
struct Received {
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<json> frames;
  bool closed = false;

  // Waits until `count` frames came (or the stream closed, or 20 s passed).
  std::vector<json> wait_for(std::size_t count) {
    std::unique_lock<std::mutex> lock(mutex);
    arrived.wait_for(lock, std::chrono::seconds(20), [&] { return frames.size() >= count || closed; });
    return frames;
  }

  // Waits until a frame satisfies `wanted` (or the stream closed, or 20 s passed); that frame,
  // or null.
  template <class Predicate>
  json wait_until(Predicate wanted) {
    std::unique_lock<std::mutex> lock(mutex);
    json found;
    arrived.wait_for(lock, std::chrono::seconds(20), [&] {
      const auto it = std::find_if(frames.begin(), frames.end(), wanted);
      if (it != frames.end()) found = *it;
      return it != frames.end() || closed;
    });
    return found;
  }
};

int on_frame(mg_connection* /*conn*/, int bits, char* data, std::size_t size, void* user) {
  auto& r = *static_cast<Received*>(user);
  if ((bits & 0x0f) != MG_WEBSOCKET_OPCODE_TEXT) return 1;
  std::lock_guard<std::mutex> lock(r.mutex);
  r.frames.push_back(test::parse_json(std::string(data, size), false));
  r.arrived.notify_all();
  return 1;
}

void on_close(const mg_connection* /*conn*/, void* user) {
  auto& r = *static_cast<Received*>(user);
  std::lock_guard<std::mutex> lock(r.mutex);
  r.closed = true;
  r.arrived.notify_all();
}

mg_connection* open_stream(int port, const std::string& token, Received& received) {
  std::array<char, 256> error{};
  const std::string path = "/api/stream?access_token=" + token;
  return mg_connect_websocket_client("127.0.0.1", port, 0, error.data(), error.size(), path.c_str(), nullptr, on_frame,
                                     on_close, &received);
}

void subscribe(mg_connection* conn, const std::string& text) {
  mg_websocket_client_write(conn, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size());
}

// Opens a stream, subscribes with `subscription`, and returns the first `count` frames (fewer
// if the stream closed or 20 s passed); the stream is closed again.
std::vector<json> stream_frames(int port, const std::string& token, const std::string& subscription,
                                std::size_t count) {
  Received received;
  mg_connection* conn = open_stream(port, token, received);
  if (conn == nullptr) return {};
  subscribe(conn, subscription);
  auto frames = received.wait_for(count);
  mg_close_connection(conn);
  return frames;
}

class ControlApiStreamTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::signal(SIGPIPE, SIG_IGN);
    mg_init_library(0);
  }

  void SetUp() override {
    const std::string tokens = dir_.file("tokens");
    write_text(tokens, "operator " + kOperator + "\nviewer " + kViewer + "\n");
    ::chmod(tokens.c_str(), 0600);
    process_ = std::make_unique<ChimeraProcess>(
        dir_, std::vector<std::string>{"run", private_copy(dir_, "net_fig4.yaml"), "--listen", "127.0.0.1:0",
                                       "--token-file", tokens});
    port_ = process_->port();
    ASSERT_GT(port_, 0) << process_->err();
  }

  void TearDown() override {
    process_->send("quit\n");
    EXPECT_EQ(process_->wait_exit(), expected_exit_) << process_->err();
  }

  TempDir dir_;
  std::unique_ptr<ChimeraProcess> process_;
  int port_ = 0;
  int expected_exit_ = 0;  // 1 after a hard task's ERROR, cleared or not (the run's exit code says so)
};

TEST_F(ControlApiStreamTest, SamplesComeAtTheClientsRate) {
  const auto frames = stream_frames(port_, kViewer, R"({"variables": ["theta_m", "theta_d"], "rate_hz": 200})", 41);
  ASSERT_GE(frames.size(), 41U);
  EXPECT_EQ(frames[0]["ok"], true) << frames[0];
  EXPECT_EQ(frames[0]["rate_hz"], 200.0);
  for (std::size_t i = 1; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i]["seq"], i - 1) << frames[i];
    EXPECT_EQ(frames[i]["values"]["theta_m"].size(), 6U) << frames[i];
    EXPECT_EQ(frames[i]["values"]["theta_d"].size(), 6U) << frames[i];
  }
  // Never faster than asked (the stream's own clock): each sample is taken at or after its grid
  // point, and each grid point after the one before lies after the sample before. A sample taken
  // late (a stalled thread) can be followed by the next one sooner than 5 ms, but the n-th after
  // the first is at least n - 1 periods after it. How much later they come depends on the
  // machine, so only the lower bound is asserted.
  const auto first = frames[1]["t_ns"].get<std::int64_t>();
  const auto last = frames.back()["t_ns"].get<std::int64_t>();
  EXPECT_GE(last - first, static_cast<std::int64_t>(frames.size() - 3) * 5'000'000);
}

// Up to the writers' rate: theta_d is written only by the 10 ms traj, so asked at 1 kHz it comes
// at 100 Hz (the ack says so, and the samples are 10 ms apart at least); with theta_m beside it,
// written by the 1 ms robot, at the rate asked.
TEST_F(ControlApiStreamTest, SamplesComeNoFasterThanTheirFastestWriter) {
  const auto slow = stream_frames(port_, kViewer, R"({"variables": ["theta_d"], "rate_hz": 1000})", 6);
  ASSERT_GE(slow.size(), 6U);
  EXPECT_EQ(slow[0]["ok"], true) << slow[0];
  EXPECT_EQ(slow[0]["rate_hz"], 100.0) << slow[0];
  const auto first = slow[1]["t_ns"].get<std::int64_t>();
  // Four grid points of 10 ms after the first sample, which may itself have been taken late: at
  // least three periods (at 1 kHz, four samples would be 4 ms apart).
  EXPECT_GE(slow.back()["t_ns"].get<std::int64_t>() - first, 3 * 10'000'000);
  const auto both = stream_frames(port_, kViewer, R"({"variables": ["theta_d", "theta_m"], "rate_hz": 1000})", 1);
  ASSERT_GE(both.size(), 1U);
  EXPECT_EQ(both[0]["rate_hz"], 1000.0) << both[0];
}

// With batch_hz the samples come together: each "samples" frame holds the samples taken since the
// last, numbered on from it, each variable's values one per sample, and none is left out.
TEST_F(ControlApiStreamTest, BatchedSamplesComeTogetherAndNoneIsLeftOut) {
  const auto frames =
      stream_frames(port_, kViewer, R"({"variables": ["theta_m", "nosuch_yet"], "rate_hz": 500, "batch_hz": 20})", 1);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0]["error"]["code"], "not_found") << frames[0];  // checked whole, as without batches
  const auto got =
      stream_frames(port_, kViewer, R"({"variables": ["theta_m", "tau_r"], "rate_hz": 500, "batch_hz": 20})", 11);
  ASSERT_GE(got.size(), 11U);
  EXPECT_EQ(got[0]["ok"], true) << got[0];
  EXPECT_EQ(got[0]["batch_hz"], 20.0);
  std::uint64_t next = 0;
  std::size_t samples = 0;
  std::int64_t last_t = -1;
  for (std::size_t i = 1; i < got.size(); ++i) {
    const json& f = got[i];
    ASSERT_EQ(f["kind"], "samples") << f;
    ASSERT_EQ(f["seq"], next) << "a sample left out before frame " << i;
    const std::size_t count = f["count"].get<std::size_t>();
    ASSERT_GE(count, 1U);
    ASSERT_LE(count, 1000U);
    ASSERT_EQ(f["t_ns"].size(), count);
    ASSERT_EQ(f["values"]["theta_m"].size(), count);
    ASSERT_EQ(f["values"]["tau_r"].size(), count);
    for (std::size_t k = 0; k < count; ++k) {
      EXPECT_GT(f["t_ns"][k].get<std::int64_t>(), last_t);  // in order, each at its own time
      last_t = f["t_ns"][k].get<std::int64_t>();
      EXPECT_EQ(f["values"]["theta_m"][k].size(), 6U) << f;
    }
    next += count;
    samples += count;
  }
  // Ten frames at 20 Hz of samples at 500 Hz: several samples a frame, never one frame each.
  EXPECT_GT(samples, 2 * (got.size() - 1)) << samples << " samples in " << got.size() - 1 << " frames";
}

// A stream holds a server thread for as long as it is open. The server keeps one for each stream
// it allows (128, HttpServer::kMaxStreams) beside its request threads: with every stream open the
// API still answers at once, and one stream more is refused at once.
TEST_F(ControlApiStreamTest, TheMostStreamsLeaveRequestsServedAndOneMoreIsRefused) {
  constexpr int kMostStreams = 128;
  std::vector<std::unique_ptr<Received>> received;
  std::vector<mg_connection*> streams;
  for (int i = 0; i < kMostStreams; ++i) {
    received.push_back(std::make_unique<Received>());
    mg_connection* conn = open_stream(port_, kViewer, *received.back());
    ASSERT_NE(conn, nullptr) << "stream " << i;
    streams.push_back(conn);
    subscribe(conn, R"({"variables": ["theta_m"], "rate_hz": 20})");
  }
  for (auto& r : received) EXPECT_GE(r->wait_for(3).size(), 3U) << "the ack and two samples";
  const auto start = std::chrono::steady_clock::now();
  const HttpResponse status = http(port_, HttpRequest{"GET", "/api/status", kViewer});
  EXPECT_EQ(status.status, 200) << status.body;
  // Without a thread free the request waits for as long as a stream stays open (for ever here);
  // 10 s leaves room for a shared machine's stalls.
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10)) << "a request waited for a thread";
  Received extra;
  EXPECT_EQ(open_stream(port_, kViewer, extra), nullptr) << "one stream more than the most";
  for (mg_connection* conn : streams) mg_close_connection(conn);
}

TEST_F(ControlApiStreamTest, AWrongTokenGetsNoStream) {
  Received received;
  EXPECT_EQ(open_stream(port_, kViewer + "x", received), nullptr);
  EXPECT_EQ(open_stream(port_, "", received), nullptr);
}

TEST_F(ControlApiStreamTest, BadSubscriptionsAreRefusedAndTheStreamGoesOn) {
  Received received;
  mg_connection* conn = open_stream(port_, kOperator, received);
  ASSERT_NE(conn, nullptr);
  subscribe(conn, "not json");
  auto frames = received.wait_for(1);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0]["error"]["code"], "bad_request") << frames[0];
  subscribe(conn, R"({"variables": ["nosuch"], "rate_hz": 10})");
  frames = received.wait_for(2);
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_EQ(frames[1]["error"]["message"], "no state variable named 'nosuch'") << frames[1];
  subscribe(conn, R"({"variables": ["theta_m"], "rate_hz": 5000})");
  frames = received.wait_for(3);
  ASSERT_EQ(frames.size(), 3U);
  EXPECT_EQ(frames[2]["error"]["code"], "bad_request") << frames[2];
  subscribe(conn, R"({"variables": ["tau_r"], "rate_hz": 100})");
  frames = received.wait_for(6);
  mg_close_connection(conn);
  ASSERT_GE(frames.size(), 6U);
  EXPECT_EQ(frames[3]["ok"], true) << frames[3];
  EXPECT_EQ(frames[4]["values"]["tau_r"].size(), 6U) << frames[4];
}

TEST_F(ControlApiStreamTest, TimingComesAtItsRateForTheTasksAsked) {
  const auto frames = stream_frames(port_, kViewer, R"({"timing_hz": 5, "tasks": ["pid"]})", 4);
  ASSERT_GE(frames.size(), 4U);
  EXPECT_EQ(frames[0]["ok"], true) << frames[0];
  EXPECT_EQ(frames[0]["timing_hz"], 5.0) << frames[0];
  EXPECT_EQ(frames[0]["rate_hz"], 0.0) << frames[0];
  std::uint64_t cycles_before = 0;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    const json& frame = frames[i];
    ASSERT_EQ(frame["kind"], "timing") << frame;
    EXPECT_EQ(frame["seq"], i - 1) << frame;
    const json& tasks = frame["stats"]["tasks"];
    ASSERT_EQ(tasks.size(), 1U) << "only the task asked for: " << frame;
    const json& pid = tasks["pid"];
    EXPECT_EQ(pid["state"], "ON") << frame;
    const auto cycles = pid["cycles"].get<std::uint64_t>();
    EXPECT_GT(cycles, cycles_before) << "pid runs at 1 kHz: more cycles in every frame";
    cycles_before = cycles;
    EXPECT_FALSE(pid["histograms"]["latency_ns"].empty()) << frame;
  }
  // At 5 Hz, on the stream's own grid from the subscription: the n-th frame (from 0) is sent at
  // or after n * 200 ms, never sooner (later on a loaded machine).
  for (std::size_t i = 1; i < frames.size(); ++i)
    EXPECT_GE(frames[i]["t_ns"].get<std::int64_t>(), static_cast<std::int64_t>(i - 1) * 200'000'000) << frames[i];
}

TEST_F(ControlApiStreamTest, StateChangesSwitchesAndErrorsComeAsEvents) {
  Received received;
  mg_connection* conn = open_stream(port_, kOperator, received);
  ASSERT_NE(conn, nullptr);
  subscribe(conn, R"({"events": true})");
  ASSERT_EQ(received.wait_for(1).at(0)["ok"], true);
  auto event = [&](const json& wanted) {
    return received.wait_until([&](const json& frame) {
      if (frame.value("kind", "") != "event") return false;
      const json& got = frame.at("event");
      const auto items = wanted.items();
      return std::all_of(items.begin(), items.end(), [&](const auto& item) {
        return got.contains(item.key()) && got.at(item.key()) == item.value();
      });
    });
  };

  ASSERT_EQ(command(port_, kOperator, "off traj").status, 200);
  EXPECT_FALSE(event({{"type", "state"}, {"task", "traj"}, {"from", "ON"}, {"to", "OFF"}}).is_null());
  ASSERT_EQ(command(port_, kOperator, "on traj").status, 200);
  EXPECT_FALSE(event({{"type", "state"}, {"task", "traj"}, {"from", "OFF"}, {"to", "ON"}}).is_null());

  ASSERT_EQ(command(port_, kOperator, "switch loaded").status, 200);
  const json switched = event({{"type", "switch"}, {"to", "loaded"}});
  ASSERT_FALSE(switched.is_null());
  EXPECT_EQ(switched["event"]["from"], "pid_control") << switched;
  EXPECT_EQ(switched["event"]["on"], json::array({"load"})) << switched;
  EXPECT_FALSE(event({{"type", "state"}, {"task", "load"}, {"to", "ON"}}).is_null());

  // faulty overruns its budget on every other cycle: a hard task's overrun puts it in ERROR on
  // its own thread, and the feed sees it at the run's next look, with the event that says why.
  expected_exit_ = 1;
  ASSERT_EQ(command(port_, kOperator, "spawn faulty").status, 200);
  ASSERT_EQ(command(port_, kOperator, "on faulty").status, 200);
  EXPECT_FALSE(event({{"type", "state"}, {"task", "faulty"}, {"to", "ERROR"}}).is_null());
  const json why = event({{"type", "log"}, {"task", "faulty"}});
  ASSERT_FALSE(why.is_null());
  EXPECT_FALSE(why["event"]["text"].get<std::string>().empty()) << why;
  ASSERT_EQ(command(port_, kOperator, "clear faulty").status, 200);
  EXPECT_FALSE(event({{"type", "state"}, {"task", "faulty"}, {"from", "ERROR"}, {"to", "OFF"}}).is_null());
  mg_close_connection(conn);

  // The numbers rise by one from item to item: nothing was left out between them.
  std::lock_guard<std::mutex> lock(received.mutex);
  std::int64_t last = -1;
  for (const auto& frame : received.frames) {
    if (frame.value("kind", "") != "event") continue;
    if (last >= 0) {
      EXPECT_EQ(frame["seq"].get<std::int64_t>(), last + 1) << frame;
    }
    last = frame["seq"].get<std::int64_t>();
  }
}

TEST_F(ControlApiStreamTest, SubscriptionsOfTimingAndEventsAreCheckedWhole) {
  Received received;
  mg_connection* conn = open_stream(port_, kViewer, received);
  ASSERT_NE(conn, nullptr);
  const std::vector<std::pair<std::string, std::string>> refused = {
      {R"({"variables": ["theta_m"], "rate_hz": 10, "colour": "red"})", "bad_request"},
      {R"({"rate_hz": 10})", "bad_request"},
      {R"({"batch_hz": 10})", "bad_request"},
      {R"({"variables": ["theta_m"], "rate_hz": 10, "batch_hz": 0})", "bad_request"},
      {R"({"variables": ["theta_m"], "rate_hz": 10, "batch_hz": "often"})", "bad_request"},
      {R"({"timing_hz": 50})", "bad_request"},
      {R"({"tasks": ["pid"]})", "bad_request"},
      {R"({"events": "yes"})", "bad_request"},
      {R"({})", "bad_request"},
      {R"({"timing_hz": 1, "tasks": ["pid", "nosuch"]})", "not_found"},
  };
  for (std::size_t i = 0; i < refused.size(); ++i) {
    subscribe(conn, refused[i].first);
    const auto frames = received.wait_for(i + 1);
    ASSERT_EQ(frames.size(), i + 1) << refused[i].first;
    EXPECT_EQ(frames[i]["error"]["code"], refused[i].second) << refused[i].first << ": " << frames[i];
  }
  EXPECT_EQ(received.wait_for(refused.size()).back()["error"]["message"], "no task named 'nosuch'");
  // After all of them the stream takes a good one, the three parts at once.
  subscribe(conn, R"({"variables": ["theta_m"], "rate_hz": 50, "timing_hz": 2, "events": true})");
  const json timing = received.wait_until([](const json& f) { return f.value("kind", "") == "timing"; });
  const json sample = received.wait_until([](const json& f) { return f.value("kind", "") == "sample"; });
  mg_close_connection(conn);
  EXPECT_EQ(received.wait_for(refused.size() + 1).at(refused.size())["ok"], true);
  EXPECT_EQ(timing["stats"]["tasks"].size(), 5U) << "every task without a filter: " << timing;
  EXPECT_EQ(sample["values"]["theta_m"].size(), 6U) << sample;
}

TEST_F(ControlApiStreamTest, AStalledStreamSlowsNeitherOtherStreamsNorTasks) {
  // A client that subscribes at 1 kHz and never reads: its bytes pile up until its socket is
  // full and its stream's thread blocks.
  const int fd = connect_to(port_);
  ASSERT_GE(fd, 0);
  const int small = 4096;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  const std::string handshake = "GET /api/stream?access_token=" + kViewer +
                                " HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                                "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  ASSERT_GT(::send(fd, handshake.data(), handshake.size(), MSG_NOSIGNAL), 0);
  const std::string text = R"({"variables": ["theta_m", "theta_d", "tau_r"], "rate_hz": 1000})";
  std::string frame{static_cast<char>(0x81), static_cast<char>(0x80 | text.size()), 0, 0, 0, 0};  // masked, key 0
  frame += text;
  ASSERT_GT(::send(fd, frame.data(), frame.size(), MSG_NOSIGNAL), 0);
  std::this_thread::sleep_for(std::chrono::seconds(1));

  auto cycles = [&] {
    const json doc = test::parse_json(http(port_, HttpRequest{"GET", "/api/status", kViewer}).body, false);
    std::uint64_t total = 0;
    for (const auto& t : doc["status"]["tasks"]) total += t["cycles"].get<std::uint64_t>();
    return total;
  };
  const std::uint64_t before = cycles();
  const auto frames = stream_frames(port_, kViewer, R"({"variables": ["theta_m"], "rate_hz": 100})", 11);
  EXPECT_GE(frames.size(), 11U);
  EXPECT_GT(cycles(), before);
  ::close(fd);
}

}  // namespace
}  // namespace chimera::test
