#include "http_client.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdio>

#include <nlohmann/json.hpp>

namespace chimera::test {

namespace {

bool send_all(int fd, std::string_view data) {
  while (!data.empty()) {
    const ssize_t n = ::send(fd, data.data(), data.size(), MSG_NOSIGNAL);
    if (n <= 0) return false;
    data.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

HttpResponse parse(const std::string& raw) {
  HttpResponse r;
  const auto head_end = raw.find("\r\n\r\n");
  if (head_end == std::string::npos) return r;
  const std::string head = raw.substr(0, head_end);
  if (std::sscanf(head.c_str(), "HTTP/1.%*d %d", &r.status) != 1) r.status = 0;
  std::size_t line_start = head.find("\r\n");
  while (line_start != std::string::npos && line_start < head.size()) {
    line_start += 2;
    const auto line_end = head.find("\r\n", line_start);
    const std::string line = head.substr(line_start, line_end - line_start);
    const auto colon = line.find(':');
    if (colon != std::string::npos) {
      std::string value = line.substr(colon + 1);
      while (!value.empty() && value.front() == ' ') value.erase(0, 1);
      r.headers[lower(line.substr(0, colon))] = value;
    }
    line_start = line_end;
  }
  r.body = raw.substr(head_end + 4);
  return r;
}

}  // namespace

int connect_to(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): the sockets API takes sockaddr*
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

HttpResponse http(int port, const HttpRequest& request, int timeout_ms) {
  const int fd = connect_to(port);
  if (fd < 0) return {};
  std::string head = request.method + " " + request.path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n";
  if (!request.authorization.empty())
    head += "Authorization: " + request.authorization + "\r\n";
  else if (!request.token.empty())
    head += "Authorization: Bearer " + request.token + "\r\n";
  std::string body = request.body;
  if (request.chunked) {
    head += "Transfer-Encoding: chunked\r\n";
    std::string chunks;
    constexpr std::size_t kChunk = 4096;
    for (std::size_t i = 0; i < body.size(); i += kChunk) {
      const std::string part = body.substr(i, kChunk);
      char size[32];
      std::snprintf(size, sizeof size, "%zx\r\n", part.size());
      chunks += size + part + "\r\n";
    }
    body = chunks + "0\r\n\r\n";
  } else if (!request.declared_length.empty()) {
    head += "Content-Length: " + request.declared_length + "\r\n";
  } else if (!body.empty() || request.method == "POST") {
    head += "Content-Length: " + std::to_string(body.size()) + "\r\n";
  }
  if (!body.empty()) head += "Content-Type: application/json\r\n";
  head += "\r\n";
  // A refused body may be left unread by the server: what does not go through is not an error.
  send_all(fd, head);
  send_all(fd, body);

  std::string raw;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  char buffer[8192];
  while (true) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    raw.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return parse(raw);
}

HttpResponse command(int port, const std::string& token, const std::string& line) {
  HttpRequest request;
  request.method = "POST";
  request.path = "/api/command";
  request.token = token;
  request.body = nlohmann::json{{"command", line}}.dump();
  return http(port, request);
}

}  // namespace chimera::test
