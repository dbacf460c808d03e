#pragma once
// The network control API on HTTP, served by civetweb: /api/ is ControlApi, / a placeholder
// page until the browser's page (issue 14, section 2) is served there.

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>

#include "chimera/core/result.hpp"
#include "chimera/net/control_api.hpp"
#include "chimera/net/listen_address.hpp"

// civetweb's types, declared only: civetweb.h stays out of every header.
struct mg_context;
struct mg_connection;

namespace chimera::net {

class HttpServer {
 public:
  /// Request threads: each serves one connection at a time, so this many clients are served at
  /// once (more wait in the accept queue); a client that stalls holds one for request_timeout.
  static constexpr int kThreads = 16;
  /// How long a request may take to arrive, and a reply to be taken by the client, before the
  /// connection is dropped: a stalled or slow client frees its thread after this.
  static constexpr int kRequestTimeoutMs = 5000;
  /// Open WebSocket streams at most (each has a thread of its own, and holds a server thread
  /// beside the request threads); more are refused at once. An Onika page holds two: 64 pages
  /// open at once, or a hundred scripts' streams.
  static constexpr int kMaxStreams = 128;

  /// Listens on `address` and serves `api` until stop() or destruction. `api` must outlive
  /// the server. An address that cannot be bound is an Errc::kSystem error naming it.
  static Result<std::unique_ptr<HttpServer>> start(ControlApi& api, const ListenAddress& address);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// The port bound (the system's choice for port 0).
  [[nodiscard]] int port() const { return port_; }
  /// "http://127.0.0.1:PORT/" with the bound port.
  [[nodiscard]] std::string url() const;

  /// Refuses new requests (503), ends pending waits, and joins the request threads (each within
  /// kRequestTimeoutMs). Idempotent.
  void stop();

 private:
  HttpServer(ControlApi& api, ListenAddress address) : api_(api), address_(std::move(address)) {}
  static int serve_api(mg_connection* conn, void* self);
  static int serve_page(mg_connection* conn, void* self);
  static int stream_connect(const mg_connection* conn, void* self);
  static void stream_ready(mg_connection* conn, void* self);
  static int stream_data(mg_connection* conn, int bits, char* data, std::size_t size, void* self);
  static void stream_close(const mg_connection* conn, void* self);

  ControlApi& api_;
  ListenAddress address_;
  mg_context* context_ = nullptr;
  int port_ = 0;
  std::atomic<int> streams_{0};  // open WebSocket streams; relaxed: a bound, not a handshake
};

}  // namespace chimera::net
