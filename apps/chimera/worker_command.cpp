// chimera __worker --file FILE --process NAME --table NAME --socket-fd N --block-fd N --life N [--config NAME]
// [--no-realtime] [--cpu-time] [--rt-check] [--history-fd N --record-seconds S] [--bell TASK:FD ...]: a module process
// (docs/processes.md). Not for people: the main process of `chimera run` starts it, and it is left out of the help.

#include <charconv>
#include <cstdlib>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "chimera/control/module_process_main.hpp"
#include "chimera/module/registry.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "load_file.hpp"

namespace chimera::cli {

int worker_command(int argc, char** argv) {
  CLI::App app{"A module process of chimera run (started by it)", "chimera __worker"};
  std::string file;
  std::string config;
  ModuleProcessArgs args;
  bool no_realtime = false;
  app.add_option("--file", file)->required();
  app.add_option("--process", args.process)->required();
  app.add_option("--table", args.table)->required();
  app.add_option("--socket-fd", args.socket_fd)->required();
  app.add_option("--block-fd", args.block_fd)->required();
  app.add_option("--life", args.life)->required();
  app.add_option("--history-fd", args.history_fd);
  std::vector<std::string> bells;  // TASK:FD, one an aperiodic task
  app.add_option("--bell", bells);
  std::string record_seconds =
      "0";  // read with strtod, as fmt wrote it: exactly that double (CLI11 goes through long double)
  app.add_option("--record-seconds", record_seconds);
  auto* config_opt = app.add_option("--config", config);
  app.add_flag("--no-realtime", no_realtime);
  app.add_flag("--cpu-time", args.measure_cpu_time);
  app.add_flag("--rt-check", args.rt_check);
  try {
    app.parse(argc - 1, argv + 1);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitInvalid;
  }
  args.realtime_priorities = !no_realtime;
  args.record_seconds = std::strtod(record_seconds.c_str(), nullptr);
  for (const std::string& bell : bells) {
    std::size_t task = 0;
    int fd = -1;
    const char* end = bell.data() + bell.size();
    const auto [colon, task_error] = std::from_chars(bell.data(), end, task);
    if (task_error != std::errc() || colon == end || *colon != ':') return kExitInvalid;
    if (const auto [rest, fd_error] = std::from_chars(colon + 1, end, fd); fd_error != std::errc() || rest != end)
      return kExitInvalid;
    args.bells.emplace_back(task, fd);
  }
  if (config_opt->count() > 0) args.configuration = config;
  // The same file and plugins as the main process: the tasks' indices are the same.
  auto spec = load_file(file, args.configuration);
  if (!spec) return kExitInvalid;
  return run_module_process(*spec, Registry::global(), args);
}

}  // namespace chimera::cli
