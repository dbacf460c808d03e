// The chimera command: verify, run and inspect subsystems (contract section 2).

#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>
#include <spdlog/cfg/env.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "chimera/config/loader.hpp"
#include "chimera/module/version.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "network.hpp"

namespace {

using chimera::cli::kExitInvalid;
using chimera::cli::kExitOk;

// Replies and tables go to stdout; diagnostics must never mix into them.
void log_to_stderr() {
  spdlog::set_default_logger(spdlog::stderr_color_mt("chimera"));
  spdlog::set_pattern("chimera: %^%l%$: %v");
  spdlog::cfg::load_env_levels();  // SPDLOG_LEVEL=debug for more
}

CLI::Validator duration_validator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        auto ns = chimera::parse_duration_ns(text);
        if (!ns) return ns.error().message;
        if (*ns <= 0) return "the duration must be positive";
        return {};
      },
      "DURATION");
}

int run_main(int argc, char** argv) {
  log_to_stderr();
  // A module process of chimera run: not a command for people, so not in the help.
  if (argc >= 2 && std::string_view(argv[1]) == "__worker") return chimera::cli::worker_command(argc, argv);

  CLI::App app{"Dynamically reconfigurable real-time software from port-based objects.", "chimera"};
  app.require_subcommand(1);
  app.set_version_flag("--version", chimera::version_text());

  chimera::cli::VerifyArgs verify;
  std::string verify_config;
  auto* verify_cmd = app.add_subcommand("verify", "Check a subsystem file and every configuration (or one)");
  verify_cmd->add_option("FILE", verify.file, "subsystem file (YAML)")->required();
  auto* verify_config_opt = verify_cmd->add_option("--config", verify_config, "check only this configuration");

  chimera::cli::RunArgs run;
  std::string run_config;
  std::string run_for;
  std::string run_clock = "real";
  std::string run_stats;
  auto* run_cmd = app.add_subcommand("run", "Run a subsystem; a shell on a terminal, commands from stdin otherwise");
  run_cmd->add_option("FILE", run.file, "subsystem file (YAML)")->required();
  auto* run_config_opt =
      run_cmd->add_option("--config", run_config, "configuration to start (default: the file's start)");
  auto* run_for_opt =
      run_cmd->add_option("--for", run_for, "stop after this long (e.g. 2s)")->check(duration_validator());
  run_cmd->add_option("--clock", run_clock, "real (wall clock) or virtual (simulated, deterministic)")
      ->check(CLI::IsMember({"real", "virtual"}))
      ->capture_default_str();
  auto* run_stats_opt = run_cmd->add_option("--stats-json", run_stats, "write per-task timing figures here at exit");
  run_cmd->add_flag("--rt-check", run.rt_check,
                    "count allocations inside each task's on/cycle/off/sync (rt violations in the timing table)");
  std::string run_record = "10s";
  std::string run_dump_dir;
  run_cmd
      ->add_option("--record", run_record,
                   "flight recorder: keep this long of every variable and task's timing in memory (off: none)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            return text == "off" ? std::string() : duration_validator()(text);
          },
          "DURATION|off"))
      ->capture_default_str();
  auto* run_dump_dir_opt = run_cmd->add_option(
      "--dump-dir", run_dump_dir, "where the recorder's dumps go (default: chimera-dumps below $CHIMERA_LOG_DIR or .)");
  run_cmd->add_flag("--dump-at-exit", run.dump_at_exit, "write the recorder's last seconds once more as the run ends");
  chimera::cli::add_listen_options(*run_cmd, run);
  chimera::cli::RunArgs serve;
  auto* serve_cmd = chimera::cli::add_serve_command(app, serve);

  chimera::cli::AnalyzeArgs analyze;
  auto* analyze_cmd = chimera::cli::add_analyze_command(app, analyze);
  chimera::cli::ProfileArgs profile;
  auto* profile_cmd = chimera::cli::add_profile_command(app, profile);

  chimera::cli::ModulesArgs modules;
  std::string modules_name;
  auto* modules_cmd = app.add_subcommand("modules", "List the module library, or one module's ports and parameters");
  auto* modules_name_opt = modules_cmd->add_option("NAME", modules_name, "a module type");
  modules_cmd->add_option("--plugin", modules.plugins,
                          "also load this module library (a path, or a name on CHIMERA_MODULE_PATH); repeatable");

  chimera::cli::NewModuleArgs new_module;
  std::string new_module_lang = "cpp";
  auto* new_module_cmd =
      app.add_subcommand("new-module", "Write a folder with a module library to build outside the tree and load");
  new_module_cmd->add_option("NAME", new_module.name, "the module's name (lower case, digits, _)")->required();
  new_module_cmd->add_option("--lang", new_module_lang, "cpp or c")
      ->check(CLI::IsMember({"cpp", "c"}))
      ->capture_default_str();
  new_module_cmd->add_option("--dir", new_module.dir, "where to create the folder NAME/")->capture_default_str();

  chimera::cli::PlotArgs plot;
  std::string plot_output;
  auto* plot_cmd = app.add_subcommand("plot", "Draw a data_logger log (CSV) as a picture (PNG)");
  plot_cmd->add_option("LOG", plot.log, "a CSV file written by a data_logger task")->required();
  auto* plot_output_opt = plot_cmd->add_option("-o,--output", plot_output, "the picture (default: LOG with .png)");
  plot_cmd->add_option("--vars", plot.variables, "only these variables, comma-separated");
  plot_cmd->add_option("--title", plot.title, "the picture's title (default: the log's file name)");

  chimera::cli::ReplayArgs replay;
  auto* replay_cmd = app.add_subcommand(
      "replay", "Run one task of a flight-recorder dump on its recorded inputs (virtual clock) and compare its outputs");
  replay_cmd->add_option("DUMP", replay.dump, "a dump's directory (variables.csv, subsystem.yaml, ...)")->required();
  replay_cmd->add_option("--task", replay.task, "the task to run")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Help is a success; every other problem with the command line is exit 2, not CLI11's codes.
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitInvalid;
  }

  if (verify_cmd->parsed()) {
    if (verify_config_opt->count() > 0) verify.config = verify_config;
    return chimera::cli::verify_command(verify);
  }
  if (analyze_cmd->parsed()) return chimera::cli::analyze_command(analyze);
  if (profile_cmd->parsed()) return chimera::cli::profile_command(profile);
  if (run_cmd->parsed()) {
    if (run_config_opt->count() > 0) run.config = run_config;
    if (run_for_opt->count() > 0) run.for_ns = *chimera::parse_duration_ns(run_for);
    if (run_stats_opt->count() > 0) run.stats_json = run_stats;
    run.record_ns = run_record == "off" ? 0 : *chimera::parse_duration_ns(run_record);
    if (run_dump_dir_opt->count() > 0) run.dump_dir = run_dump_dir;
    run.clock = run_clock == "virtual" ? chimera::ClockKind::kVirtual : chimera::ClockKind::kReal;
    return chimera::cli::run_command(run);
  }
  if (serve_cmd->parsed()) return chimera::cli::run_command(serve);
  if (replay_cmd->parsed()) return chimera::cli::replay_command(replay);
  if (plot_cmd->parsed()) {
    if (plot_output_opt->count() > 0) plot.output = plot_output;
    return chimera::cli::plot_command(plot);
  }
  if (new_module_cmd->parsed()) {
    new_module.c = new_module_lang == "c";
    return chimera::cli::new_module_command(new_module);
  }
  if (modules_name_opt->count() > 0) modules.name = modules_name;
  return chimera::cli::modules_command(modules);
}

}  // namespace

int main(int argc, char** argv) {
  // Every expected failure is a message and an exit code; this is the last guard against a crash.
  try {
    return run_main(argc, argv);
  } catch (const std::exception& e) {
    std::fputs("chimera: internal error: ", stderr);
    std::fputs(e.what(), stderr);
    std::fputs("\n", stderr);
  } catch (...) {
    std::fputs("chimera: internal error\n", stderr);
  }
  return kExitInvalid;
}
