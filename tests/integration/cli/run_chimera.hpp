#pragma once
// Runs the chimera command in a shell with given standard input and captures what it printed.

#include <string>

namespace chimera::test {

struct Outcome {
  int exit_code = -1;  // -1: did not exit normally
  std::string out;
  std::string err;
};

/// A fresh directory for one test's files, removed by the destructor.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

std::string read_text(const std::string& path);
void write_text(const std::string& path, const std::string& text);

/// `chimera <args>` (args as one shell-quoted string) with `input` on stdin; `prefix` goes
/// before the command (e.g. "timeout -s TERM 1").
Outcome run_chimera(const TempDir& dir, const std::string& args, const std::string& input = {},
                    const std::string& prefix = {});

/// A copy of `data_dir`'s file `name` under `dir` with a subsystem name no other test process
/// uses, since a running subsystem owns the shared memory of its name.
std::string private_copy_from(const std::string& data_dir, const TempDir& dir, const std::string& name);

#ifdef CLI_DATA_DIR
/// private_copy_from the test's data folder (chimera_cli_test's DATA_DIR): defined here, in the
/// test's own file, since this helper is compiled once for every test program.
inline std::string private_copy(const TempDir& dir, const std::string& name) {
  return private_copy_from(CLI_DATA_DIR, dir, name);
}
#endif

/// `'text'` for the shell.
std::string quoted(const std::string& text);

}  // namespace chimera::test
