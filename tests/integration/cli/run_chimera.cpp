#include "run_chimera.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace chimera::test {

TempDir::TempDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "chimera_cli_XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::trunc);
  out << text;
}

std::string quoted(const std::string& text) {
  std::string q = "'";
  for (char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

Outcome run_chimera(const TempDir& dir, const std::string& args, const std::string& input, const std::string& prefix) {
  const std::string in = dir.file("stdin.txt");
  const std::string out = dir.file("stdout.txt");
  const std::string err = dir.file("stderr.txt");
  write_text(in, input);
  const std::string command =
      prefix + " " + quoted(CHIMERA_BIN) + " " + args + " <" + quoted(in) + " >" + quoted(out) + " 2>" + quoted(err);
  const int status = std::system(command.c_str());  // NOLINT(concurrency-mt-unsafe): tests run one thread
  Outcome o;
  o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = read_text(out);
  o.err = read_text(err);
  return o;
}

std::string private_copy_from(const std::string& data_dir, const TempDir& dir, const std::string& name) {
  static int copies = 0;
  std::istringstream text(read_text(data_dir + "/" + name));
  std::string copy;
  for (std::string line; std::getline(text, line);) {
    if (line.rfind("subsystem:", 0) == 0)
      line = "subsystem: cli_" + std::to_string(::getpid()) + "_" + std::to_string(copies++);
    copy += line + "\n";
  }
  std::string path = dir.file(name);
  write_text(path, copy);
  return path;
}

}  // namespace chimera::test
