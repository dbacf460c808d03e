// chimera plot LOG.csv [-o OUT.png] [--vars a,b] [--title TEXT]: draws a data_logger log with
// scripts/plot_log.py (python3 and matplotlib), installed as share/chimera/plot_log.py.

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "commands.hpp"
#include "exit_codes.hpp"

namespace chimera::cli {
namespace {

namespace fs = std::filesystem;

// Installed: PREFIX/bin/chimera and PREFIX/share/chimera/plot_log.py; in a build tree the source's.
std::string plot_script() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share" / "chimera" / "plot_log.py";
    if (fs::exists(installed, ec)) return installed.string();
  }
  const fs::path source = fs::path(CHIMERA_SOURCE_DIR) / "scripts" / "plot_log.py";
  if (fs::exists(source, ec)) return source.string();
  return {};
}

// $CHIMERA_PYTHON; else Debian's python3, where python3-matplotlib is (a python3 earlier on PATH,
// pyenv's say, may well lack it); else the first python3 on PATH.
std::string python() {
  // NOLINTNEXTLINE(concurrency-mt-unsafe): the command has one thread
  if (const char* chosen = std::getenv("CHIMERA_PYTHON"); chosen != nullptr && *chosen != '\0') return chosen;
  if (::access("/usr/bin/python3", X_OK) == 0) return "/usr/bin/python3";
  return "python3";
}

}  // namespace

int plot_command(const PlotArgs& args) {
  const std::string script = plot_script();
  if (script.empty()) {
    fmt::print(stderr, "plot: cannot find plot_log.py (share/chimera beside the installed chimera)\n");
    return kExitInvalid;
  }
  const std::string interpreter = python();
  std::vector<std::string> words{interpreter, script, args.log};
  if (args.output) words.insert(words.end(), {"-o", *args.output});
  if (!args.variables.empty()) words.insert(words.end(), {"--vars", args.variables});
  if (!args.title.empty()) words.insert(words.end(), {"--title", args.title});
  std::vector<char*> argv;
  argv.reserve(words.size() + 1);
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  ::execvp(interpreter.c_str(), argv.data());  // on success the script's exit code is chimera's
  fmt::print(stderr, "plot: cannot run {} ({}); chimera plot needs python3 with matplotlib\n", interpreter,
             std::generic_category().message(errno));
  return kExitInvalid;
}

}  // namespace chimera::cli
