#include "chimera_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <stdexcept>
#include <thread>

#include "support/text_search.hpp"

namespace chimera::test {

namespace {

bool reap(int pid, int& code, bool block) {
  int status = 0;
  const pid_t r = ::waitpid(pid, &status, block ? 0 : WNOHANG);
  if (r != pid) return false;
  code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return true;
}

}  // namespace

ChimeraProcess::ChimeraProcess(const TempDir& dir, const std::vector<std::string>& args,
                               const std::vector<std::string>& env, const std::vector<std::string>& launcher)
    : out_path_(dir.file("process.out")), err_path_(dir.file("process.err")) {
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  std::vector<std::string> words = launcher;
  words.emplace_back(CHIMERA_BIN);
  words.insert(words.end(), args.begin(), args.end());
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    ::dup2(pipe_fds[0], STDIN_FILENO);
    const int out = ::open(out_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int err = ::open(err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    // NOLINTNEXTLINE(concurrency-mt-unsafe): the child of fork, before exec
    for (const auto& e : env) ::putenv(const_cast<char*>(e.c_str()));  // NOLINT(cppcoreguidelines-pro-type-const-cast)
    std::vector<char*> argv;
    for (auto& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    ::execvp(argv[0], argv.data());  // a launcher is looked up on PATH; chimera's path is absolute
    ::_exit(127);
  }
  ::close(pipe_fds[0]);
  input_ = pipe_fds[1];
}

ChimeraProcess::~ChimeraProcess() {
  close_input();
  if (pid_ > 0 && running()) {
    ::kill(pid_, SIGTERM);
    if (wait_exit(10000) == -1 && running()) {
      ::kill(pid_, SIGKILL);
      reap(pid_, exit_code_, true);
    }
  }
}

bool ChimeraProcess::running() {
  if (pid_ <= 0) return false;
  if (reap(pid_, exit_code_, false)) {
    pid_ = -1;
    return false;
  }
  return true;
}

int ChimeraProcess::port() {
  for (int i = 0; i < 600; ++i) {
    // "control API on http://HOST:PORT/api/": the port is after the address's last colon.
    const auto address = test::text_after(err(), "control API on http://", "/ \n");
    const auto colon = address ? address->rfind(':') : std::string::npos;
    if (colon != std::string::npos && test::only_of(address->substr(colon + 1), "0123456789"))
      return std::stoi(address->substr(colon + 1));
    if (!running()) return 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return 0;
}

void ChimeraProcess::send(const std::string& text) {
  if (input_ < 0) return;
  std::string_view rest = text;
  while (!rest.empty()) {
    const ssize_t n = ::write(input_, rest.data(), rest.size());
    if (n <= 0) return;
    rest.remove_prefix(static_cast<std::size_t>(n));
  }
}

void ChimeraProcess::close_input() {
  if (input_ >= 0) ::close(input_);
  input_ = -1;
}

int ChimeraProcess::wait_exit(int timeout_ms) {
  for (int waited = 0; waited <= timeout_ms; waited += 20) {
    if (!running()) return exit_code_;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return -1;
}

std::string ChimeraProcess::out() const { return read_text(out_path_); }
std::string ChimeraProcess::err() const { return read_text(err_path_); }

}  // namespace chimera::test
