#include "chimera/net/http_server.hpp"

#include <civetweb.h>

#include <array>
#include <cstring>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "chimera/net/api_stream.hpp"
#include "page_files.hpp"

namespace chimera::net {

namespace {

int log_message(const mg_connection* /*conn*/, const char* message) {
  spdlog::warn("network: {}", message);
  return 1;  // logged here: civetweb prints nothing of its own
}

void send(mg_connection* conn, int status, std::string_view type, std::string_view body, const std::string& allow) {
  mg_response_header_start(conn, status);
  mg_response_header_add(conn, "Content-Type", type.data(), static_cast<int>(type.size()));
  const std::string length = std::to_string(body.size());
  mg_response_header_add(conn, "Content-Length", length.c_str(), -1);
  mg_response_header_add(conn, "Cache-Control", "no-store", -1);
  mg_response_header_add(conn, "X-Content-Type-Options", "nosniff", -1);
  if (status == 401) mg_response_header_add(conn, "WWW-Authenticate", "Bearer realm=\"chimera\"", -1);
  if (!allow.empty()) mg_response_header_add(conn, "Allow", allow.c_str(), -1);
  // The page runs only its own files: no inline script, nothing from another origin.
  mg_response_header_add(conn, "Content-Security-Policy",
                         "default-src 'self'; img-src 'self' data: blob:; connect-src 'self'; object-src 'none'; "
                         "frame-ancestors 'none'",
                         -1);
  mg_response_header_send(conn);
  if (!body.empty()) mg_write(conn, body.data(), body.size());
}

// The body, at most ControlApi::kMaxBodyBytes of it; false if there is more (left unread).
bool read_body(mg_connection* conn, long long declared, std::string& body) {
  constexpr auto kMax = static_cast<long long>(ControlApi::kMaxBodyBytes);
  if (declared > kMax) return false;
  std::array<char, 8192> buffer{};
  while (true) {
    const int n = mg_read(conn, buffer.data(), buffer.size());
    if (n <= 0) return true;  // the end (or a broken connection: the API sees what arrived)
    body.append(buffer.data(), static_cast<std::size_t>(n));
    if (body.size() > ControlApi::kMaxBodyBytes) return false;  // chunked, without a length
  }
}

}  // namespace

Result<std::unique_ptr<HttpServer>> HttpServer::start(ControlApi& api, const ListenAddress& address) {
  if (address.ipv6 && mg_check_feature(MG_FEATURES_IPV6) == 0)
    return make_error(Errc::kSystem, fmt::format("--listen {}: this civetweb has no IPv6", address.text(address.port)));
  std::unique_ptr<HttpServer> server(new HttpServer(api, address));
  const std::string ports = address.civetweb_ports();
  // civetweb serves a WebSocket on the thread that accepted it for as long as it is open: one
  // thread for each stream allowed beside the request threads, or a full set of streams would
  // leave no thread for requests (seen: 16 streams made every request wait for a thread).
  const std::string threads = std::to_string(kThreads + kMaxStreams);
  const std::string timeout = std::to_string(kRequestTimeoutMs);
  // No document_root: civetweb serves no file of its own, only the handlers below.
  // tcp_nodelay: civetweb writes a reply's headers and body apart; with Nagle's algorithm the
  // body then waits for the client's delayed ACK of the headers, 40 ms a request on a connection
  // kept alive (measured: 44 ms a `get`, where a new connection per request took 0.4 ms).
  std::array<const char*, 15> options{"listening_ports",
                                      ports.c_str(),
                                      "num_threads",
                                      threads.c_str(),
                                      "request_timeout_ms",
                                      timeout.c_str(),
                                      "enable_keep_alive",
                                      "yes",
                                      "keep_alive_timeout_ms",
                                      "2000",
                                      "max_request_size",
                                      "16384",
                                      "tcp_nodelay",
                                      "1",
                                      nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = log_message;
  mg_init_data init{};
  init.callbacks = &callbacks;
  init.user_data = server.get();
  init.configuration_options = options.data();
  std::array<char, 256> text{};
  unsigned code = 0;
  mg_error_data error{};
  error.code = &code;
  error.text = text.data();
  error.text_buffer_size = text.size();
  server->context_ = mg_start2(&init, &error);
  if (server->context_ == nullptr)
    return make_error(Errc::kSystem, fmt::format("--listen {}: {}", address.text(address.port), text.data()));

  std::array<mg_server_port, 1> bound{};
  if (mg_get_server_ports(server->context_, static_cast<int>(bound.size()), bound.data()) < 1) {
    server->stop();
    return make_error(Errc::kSystem, fmt::format("--listen {}: no port bound", address.text(address.port)));
  }
  server->port_ = bound[0].port;
  mg_set_request_handler(server->context_, "/api", serve_api, server.get());
  mg_set_websocket_handler(server->context_, "/api/stream", stream_connect, stream_ready, stream_data, stream_close,
                           server.get());
  mg_set_request_handler(server->context_, "/", serve_page, server.get());
  return server;
}

HttpServer::~HttpServer() { stop(); }

std::string HttpServer::url() const { return fmt::format("http://{}/", address_.text(port_)); }

void HttpServer::stop() {
  api_.close();
  if (context_ == nullptr) return;
  mg_stop(context_);  // joins the request threads
  context_ = nullptr;
}

int HttpServer::serve_api(mg_connection* conn, void* self) {
  auto& server = *static_cast<HttpServer*>(self);
  const mg_request_info* info = mg_get_request_info(conn);
  const char* authorization = mg_get_header(conn, "Authorization");
  ApiRequest request;
  request.method = info->request_method;
  request.path = info->local_uri != nullptr ? info->local_uri : "";
  request.authorization = authorization != nullptr ? authorization : "";

  std::string body;
  if (read_body(conn, info->content_length, body)) {
    request.body = body;
  } else {
    // Unread bytes are still on the way: answer (the token is still checked first), then close
    // the connection rather than drain them.
    request.body_too_large = true;
    mg_disable_connection_keep_alive(conn);
  }
  const ApiResponse response = server.api_.handle(request);
  send(conn, response.status, "application/json", response.body, response.allow);
  server.api_.sent(response);
  return response.status;
}

int HttpServer::stream_connect(const mg_connection* conn, void* self) {
  auto& server = *static_cast<HttpServer*>(self);
  const mg_request_info* info = mg_get_request_info(conn);
  // A browser cannot set headers on a WebSocket: the token may come as ?access_token= (RFC 6750).
  std::string authorization;
  if (const char* header = mg_get_header(conn, "Authorization"); header != nullptr) authorization = header;
  if (authorization.empty() && info->query_string != nullptr) {
    std::array<char, 256> token{};
    const std::string_view query = info->query_string;
    if (mg_get_var(query.data(), query.size(), "access_token", token.data(), token.size()) > 0)
      authorization = std::string("Bearer ") + token.data();
  }
  if (server.api_.closing() || !server.api_.role_of(authorization)) return 1;  // refused: closed at once
  return server.streams_.load(std::memory_order_relaxed) >= kMaxStreams ? 1 : 0;
}

void HttpServer::stream_ready(mg_connection* conn, void* self) {
  auto& server = *static_cast<HttpServer*>(self);
  server.streams_.fetch_add(1, std::memory_order_relaxed);
  auto* stream = new ApiStream(server.api_.gate(), conn);  // NOLINT(cppcoreguidelines-owning-memory): see below
  if (!stream->failure().empty()) spdlog::warn("network: a stream was refused: {}", stream->failure());
  mg_set_user_connection_data(conn, stream);  // owned until stream_close
}

int HttpServer::stream_data(mg_connection* conn, int bits, char* data, std::size_t size, void* /*self*/) {
  constexpr int kOpcodeMask = 0x0f;
  const int opcode = bits & kOpcodeMask;
  if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return 0;
  auto* stream = static_cast<ApiStream*>(mg_get_user_connection_data(conn));
  if (opcode == MG_WEBSOCKET_OPCODE_TEXT && stream != nullptr) stream->receive(std::string_view(data, size));
  return 1;
}

void HttpServer::stream_close(const mg_connection* conn, void* self) {
  auto& server = *static_cast<HttpServer*>(self);
  auto* stream = static_cast<ApiStream*>(mg_get_user_connection_data(conn));
  if (stream == nullptr) return;
  delete stream;  // NOLINT(cppcoreguidelines-owning-memory): civetweb holds it as a void* from stream_ready
  mg_set_user_connection_data(conn, nullptr);
  server.streams_.fetch_sub(1, std::memory_order_relaxed);
}

int HttpServer::serve_page(mg_connection* conn, void* /*self*/) {
  const mg_request_info* info = mg_get_request_info(conn);
  const std::string_view path = info->local_uri != nullptr ? info->local_uri : "";
  const std::string_view method = info->request_method;
  // The page's files are public (the token is asked for by the page, and every /api/ request
  // needs it): Onika's own files, embedded at build time, and nothing else.
  const PageFile* file = find_page_file(path);
  if (file == nullptr) {
    send(conn, 404, "text/plain; charset=utf-8", "not found\n", {});
    return 404;
  }
  if (method != "GET" && method != "HEAD") {
    send(conn, 405, "text/plain; charset=utf-8", "GET only\n", "GET, HEAD");
    return 405;
  }
  send(conn, 200, file->content_type, method == "HEAD" ? std::string_view{} : file->body, {});
  return 200;
}

}  // namespace chimera::net
