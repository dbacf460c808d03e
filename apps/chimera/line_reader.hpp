#pragma once
// Reads commands a line at a time from a file descriptor with a timeout, so the run loop can
// notice signals, print events and keep time while nobody types. std::getline cannot: it blocks,
// and its buffer hides pending lines from poll().

#include <string>

namespace chimera::cli {

class LineReader {
 public:
  enum class Status { kLine, kTimeout, kEnd };

  explicit LineReader(int fd) : fd_(fd) {}

  /// Waits up to `timeout_ms` for a complete line. kLine fills `line` (without the newline);
  /// kEnd comes once the input is closed and every line has been returned (a last line
  /// without a newline still counts). A signal ends the wait early with kTimeout.
  Status next(std::string& line, int timeout_ms);

 private:
  bool take_line(std::string& line);

  int fd_;
  std::string buffer_;
  bool closed_ = false;
};

}  // namespace chimera::cli
