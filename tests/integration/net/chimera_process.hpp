#pragma once
// The chimera command started as a process that keeps running while a test talks to it over
// the network: stdin is a pipe the test writes to, stdout and stderr go to files.

#include <string>
#include <vector>

#include "run_chimera.hpp"

namespace chimera::test {

class ChimeraProcess {
 public:
  /// Starts `chimera args...` in `dir`'s files; `env` entries ("NAME=value") are added. A
  /// `launcher` goes before the command and must exec it in its own place, so that pid() is
  /// chimera's (e.g. {"ip", "netns", "exec", "NAME"}: the run on another network stack).
  ChimeraProcess(const TempDir& dir, const std::vector<std::string>& args, const std::vector<std::string>& env = {},
                 const std::vector<std::string>& launcher = {});
  /// Ends the process if it still runs (SIGTERM, then SIGKILL).
  ~ChimeraProcess();
  ChimeraProcess(const ChimeraProcess&) = delete;
  ChimeraProcess& operator=(const ChimeraProcess&) = delete;

  /// The port from "control API on http://127.0.0.1:PORT/api/" on stderr; 0 if the line did not
  /// come within 60 s or the process ended first.
  int port();
  /// Writes to the process's standard input.
  void send(const std::string& text);
  /// Closes standard input (end of input).
  void close_input();
  /// Waits up to `timeout_ms` for the exit; the exit code, or -1 (then the process is killed).
  int wait_exit(int timeout_ms = 30000);
  [[nodiscard]] bool running();
  /// Its pid while it runs (-1 once reaped).
  [[nodiscard]] int pid() const { return pid_; }

  [[nodiscard]] std::string out() const;
  [[nodiscard]] std::string err() const;

 private:
  int pid_ = -1;
  int input_ = -1;
  int exit_code_ = -1;
  std::string out_path_;
  std::string err_path_;
};

}  // namespace chimera::test
