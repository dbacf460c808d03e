#pragma once
// A small HTTP/1.1 client over plain sockets for the network API's tests: one request a
// connection (Connection: close), and raw sockets for clients that misbehave on purpose.

#include <map>
#include <string>
#include <string_view>
#include <utility>

namespace chimera::test {

struct HttpResponse {
  int status = 0;                              // 0: no reply (connection refused, closed or timed out)
  std::map<std::string, std::string> headers;  // names in lower case
  std::string body;

  /// A header's value, "" if absent; `name` in lower case.
  [[nodiscard]] std::string header(const std::string& name) const {
    const auto it = headers.find(name);
    return it == headers.end() ? std::string() : it->second;
  }
};

struct HttpRequest {
  explicit HttpRequest(std::string method_ = "GET", std::string path_ = "/api/status", std::string token_ = {})
      : method(std::move(method_)), path(std::move(path_)), token(std::move(token_)) {}
  std::string method;
  std::string path;
  std::string token;          // "" sends no Authorization header
  std::string authorization;  // overrides the header's whole value when not ""
  std::string body;
  bool chunked = false;         // send the body with Transfer-Encoding: chunked
  std::string declared_length;  // overrides Content-Length (send less than declared)
};

/// Sends `request` to 127.0.0.1:`port` and reads the reply to the end, within `timeout_ms`.
HttpResponse http(int port, const HttpRequest& request, int timeout_ms = 15000);

/// POST /api/command with {"command": line}.
HttpResponse command(int port, const std::string& token, const std::string& line);

/// A connected socket to 127.0.0.1:`port` (-1 on failure); the caller closes it.
int connect_to(int port);

}  // namespace chimera::test
