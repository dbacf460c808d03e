#pragma once
// The network control API (docs/control-api.md): HTTP requests under /api/ turned into the
// shell's commands on a ControlGate, and their replies into JSON. Free of any HTTP library, so
// that it is tested without sockets; src/net/http_server.cpp carries it over civetweb.

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "chimera/control/command.hpp"
#include "chimera/net/access_tokens.hpp"
#include "chimera/net/control_gate.hpp"
#include "chimera/net/opened_files.hpp"

namespace chimera::net {

/// One request as the transport received it; the body is whole (and at most kMaxBodyBytes).
struct ApiRequest {
  std::string_view method;         // "GET", "POST", ...
  std::string_view path;           // "/api/command", without the query
  std::string_view authorization;  // the Authorization header's value, "" if none
  std::string_view body;
  bool body_too_large = false;  // the transport left a body larger than kMaxBodyBytes unread
};

/// One reply: an HTTP status and a JSON document.
struct ApiResponse {
  int status = 200;
  std::string body;   // JSON, one line
  std::string allow;  // for 405: the methods the path takes ("GET")
  /// A `quit` was accepted: once the reply is on its way (ControlApi::sent), the subsystem stops.
  bool stops_subsystem = false;
};

/// Whether `verb` can change the subsystem (or its time): only operators may send it.
bool verb_needs_operator(Verb verb);

class ControlApi {
 public:
  /// The largest request body taken; a larger one is refused unread (413).
  static constexpr std::size_t kMaxBodyBytes = std::size_t{64} * 1024;
  /// The longest `wait` over the network: a request thread is not parked for longer.
  static constexpr std::int64_t kMaxWaitNs = 60'000'000'000;

  /// `on_quit` is called once the reply to an accepted `quit` was sent (sent()): the owner of
  /// the subsystem stops it. Before, the server could stop before the reply left, and the client
  /// saw its connection closed instead of the reply.
  ControlApi(ControlGate& gate, AccessTokens tokens, std::function<void()> on_quit = {});

  /// Carries out one request: 401 without a known token (nothing else is looked at), then 404,
  /// 405, 413, 400 for what is wrong with the request, 403 for a viewer's write, 409 for a
  /// command the subsystem refused (nothing changed), 200 otherwise. Any thread; commands are
  /// serialised by the gate. Not real-time safe.
  ApiResponse handle(const ApiRequest& request);

  /// The transport calls this after it wrote `response`: a quit's reply has left, so the
  /// subsystem may stop now.
  void sent(const ApiResponse& response);

  /// The role of an Authorization header's bearer token; none for no or a wrong token.
  [[nodiscard]] std::optional<Role> role_of(std::string_view authorization) const;
  /// The gate the API drives, for the streams beside it.
  [[nodiscard]] ControlGate& gate() const { return gate_; }
  /// Whether close() was called.
  [[nodiscard]] bool closing() const { return closing_; }

  /// From now on requests get 503 and a `wait` under way returns early: the server is closing.
  void close();

  /// The reply to a body that was too large, for the transport that refuses it unread.
  static ApiResponse too_large();
  /// A JSON error reply {"ok": false, "error": {"code": CODE, "message": MESSAGE}}.
  static ApiResponse error(int status, std::string_view code, std::string_view message);

 private:
  ApiResponse command(Role role, std::string_view body);
  ApiResponse status();
  ApiResponse variable(std::string_view name);
  ApiResponse wait(const Command& command);
  ApiResponse open(Role role, std::string_view body);
  // The reply of a GET endpoint (is_document() in control_api.cpp says which paths are).
  ApiResponse document(Role role, std::string_view path);

  ControlGate& gate_;
  AccessTokens tokens_;
  std::function<void()> on_quit_;
  std::atomic<bool> closing_{false};  // seq_cst: set once at close, read by waits; rare, simplest
  OpenedFiles opened_;                // the files POST /api/open wrote; used under the gate
};

}  // namespace chimera::net
