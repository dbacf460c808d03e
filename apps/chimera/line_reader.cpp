#include "line_reader.hpp"

#include <poll.h>
#include <unistd.h>

#include <array>
#include <cerrno>

namespace chimera::cli {

bool LineReader::take_line(std::string& line) {
  const auto newline = buffer_.find('\n');
  if (newline == std::string::npos) {
    if (!closed_ || buffer_.empty()) return false;
    line = std::move(buffer_);
    buffer_.clear();
    return true;
  }
  line.assign(buffer_, 0, newline);
  buffer_.erase(0, newline + 1);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

LineReader::Status LineReader::next(std::string& line, int timeout_ms) {
  for (;;) {
    if (take_line(line)) return Status::kLine;
    if (closed_) return Status::kEnd;

    pollfd pfd{fd_, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, timeout_ms);
    if (ready == 0 || (ready < 0 && errno == EINTR)) return Status::kTimeout;
    if (ready < 0) {
      closed_ = true;  // an unusable descriptor reads as the end of input
      continue;
    }
    std::array<char, 4096> chunk{};
    const ssize_t n = ::read(fd_, chunk.data(), chunk.size());
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) return Status::kTimeout;
    if (n <= 0) {
      closed_ = true;
      continue;
    }
    buffer_.append(chunk.data(), static_cast<std::size_t>(n));
  }
}

}  // namespace chimera::cli
