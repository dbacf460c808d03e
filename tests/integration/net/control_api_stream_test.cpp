// WebSocket streams of state variables from a real `chimera run --listen` (real clock): samples
// at the client's rate, tokens, bad subscriptions, and a stalled client that slows nobody.

#include <civetweb.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

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
};

int on_frame(mg_connection* /*conn*/, int bits, char* data, std::size_t size, void* user) {
  auto& r = *static_cast<Received*>(user);
  if ((bits & 0x0f) != MG_WEBSOCKET_OPCODE_TEXT) return 1;
  std::lock_guard<std::mutex> lock(r.mutex);
  r.frames.push_back(json::parse(std::string(data, size), nullptr, false));
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
    EXPECT_EQ(process_->wait_exit(), 0) << process_->err();
  }

  TempDir dir_;
  std::unique_ptr<ChimeraProcess> process_;
  int port_ = 0;
};

TEST_F(ControlApiStreamTest, SamplesComeAtTheClientsRate) {
  Received received;
  mg_connection* conn = open_stream(port_, kViewer, received);
  ASSERT_NE(conn, nullptr);
  subscribe(conn, R"({"variables": ["theta_m", "theta_d"], "rate_hz": 200})");
  const auto frames = received.wait_for(41);
  mg_close_connection(conn);
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

// A stream holds a server thread for as long as it is open. The server keeps one for each stream
// it allows (32, HttpServer::kMaxStreams) beside its request threads: with every stream open the
// API still answers at once, and one stream more is refused at once.
TEST_F(ControlApiStreamTest, TheMostStreamsLeaveRequestsServedAndOneMoreIsRefused) {
  constexpr int kMostStreams = 32;
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
    const json doc = json::parse(http(port_, HttpRequest{"GET", "/api/status", kViewer}).body, nullptr, false);
    std::uint64_t total = 0;
    for (const auto& t : doc["status"]["tasks"]) total += t["cycles"].get<std::uint64_t>();
    return total;
  };
  const std::uint64_t before = cycles();
  Received received;
  mg_connection* conn = open_stream(port_, kViewer, received);
  ASSERT_NE(conn, nullptr);
  subscribe(conn, R"({"variables": ["theta_m"], "rate_hz": 100})");
  const auto frames = received.wait_for(11);
  mg_close_connection(conn);
  EXPECT_GE(frames.size(), 11U);
  EXPECT_GT(cycles(), before);
  ::close(fd);
}

}  // namespace
}  // namespace chimera::test
