#pragma once
// The subcommands of the chimera command, one file each; main.cpp only parses the command line.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "chimera/analysis/task_model.hpp"
#include "chimera/control/subsystem.hpp"

namespace CLI {  // NOLINT(readability-identifier-naming): CLI11's namespace, forward-declared
class App;
}  // namespace CLI

namespace chimera::cli {

struct VerifyArgs {
  std::string file;
  std::optional<std::string> config;
};
/// `chimera verify FILE [--config NAME]`; returns the exit code.
int verify_command(const VerifyArgs& args);
/// chimera __worker ...: a module process of chimera run (docs/processes.md); argv[1] is "__worker".
int worker_command(int argc, char** argv);

struct RunArgs {
  std::string file;
  std::optional<std::string> config;
  std::optional<std::int64_t> for_ns;
  ClockKind clock = ClockKind::kReal;
  std::optional<std::string> stats_json;
  bool rt_check = false;                  // count allocations in the tasks' real-time methods
  std::optional<std::string> listen;      // --listen [ADDR:]PORT: the network control API
  std::optional<std::string> token_file;  // --token-file FILE: its tokens
  // The flight recorder (docs/flight-recorder.md): --record DURATION of history (0: off), dumps
  // below --dump-dir (when a task enters ERROR, on `dump`), and one more at exit with --dump-at-exit.
  std::int64_t record_ns = 10'000'000'000;
  std::optional<std::string> dump_dir;
  bool dump_at_exit = false;
};
/// `chimera run FILE ...`, and `chimera serve` (file empty: an empty subsystem); returns the exit code.
int run_command(const RunArgs& args);

struct AnalyzeArgs {
  std::string file;
  std::optional<std::string> config;
  std::optional<std::string> wcet_from;
  std::int64_t overhead_ns = analysis::kDefaultOverheadNs;
  bool json = false;  // one JSON document on stdout instead of the text report
};
/// Declares `chimera analyze` and its options on `app`; parsing fills `args`.
CLI::App* add_analyze_command(CLI::App& app, AnalyzeArgs& args);
/// `chimera analyze FILE [--config NAME] [--wcet-from PROFILE] [--overhead DURATION] [--json]`; returns the
/// exit code.
int analyze_command(const AnalyzeArgs& args);

struct ProfileArgs {
  std::string file;
  std::string output;
  std::optional<std::string> config;
  std::int64_t for_ns = 10'000'000'000;
  std::string clock = "real";
  double margin = 1.2;
};
/// Declares `chimera profile` and its options on `app`; parsing fills `args`.
CLI::App* add_profile_command(CLI::App& app, ProfileArgs& args);
/// `chimera profile FILE -o PROFILE [--config NAME] [--for DURATION] [--clock C] [--margin X]`.
int profile_command(const ProfileArgs& args);

struct ModulesArgs {
  std::optional<std::string> name;
  std::vector<std::string> plugins;  // --plugin LIB, loaded besides every library on CHIMERA_MODULE_PATH
};
/// `chimera modules [NAME] [--plugin LIB]...`; returns the exit code.
int modules_command(const ModulesArgs& args);

struct NewModuleArgs {
  std::string name;
  bool c = false;         // --lang c: the C template
  std::string dir = ".";  // where the module's folder goes
};
/// `chimera new-module NAME [--lang cpp|c] [--dir DIR]`; returns the exit code.
int new_module_command(const NewModuleArgs& args);

struct PlotArgs {
  std::string log;                    // a data_logger CSV file
  std::optional<std::string> output;  // default: the log's name with .png
  std::string variables;              // comma-separated; empty: all
  std::string title;
};
struct ReplayArgs {
  std::string dump;  // a flight-recorder dump's directory
  std::string task;
};

/// `chimera replay DUMP --task NAME`: the task run on its recorded inputs on the virtual clock,
/// its outputs compared with the recorded ones. Exit 1 if it entered ERROR, 2 on bad input.
int replay_command(const ReplayArgs& args);

/// `chimera plot LOG.csv [-o OUT.png] [--vars a,b] [--title TEXT]`; returns the exit code.
int plot_command(const PlotArgs& args);

}  // namespace chimera::cli
