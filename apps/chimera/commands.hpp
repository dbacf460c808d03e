#pragma once
// The subcommands of the chimera command, one file each; main.cpp only parses the command line.

#include <cstdint>
#include <optional>
#include <string>

#include "chimera/analysis/task_model.hpp"
#include "chimera/exec/subsystem.hpp"

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

struct RunArgs {
  std::string file;
  std::optional<std::string> config;
  std::optional<std::int64_t> for_ns;
  ClockKind clock = ClockKind::kReal;
  std::optional<std::string> stats_json;
};
/// `chimera run FILE ...`; returns the exit code.
int run_command(const RunArgs& args);

struct AnalyzeArgs {
  std::string file;
  std::optional<std::string> config;
  std::optional<std::string> wcet_from;
  std::int64_t overhead_ns = analysis::kDefaultOverheadNs;
};
/// Declares `chimera analyze` and its options on `app`; parsing fills `args`.
CLI::App* add_analyze_command(CLI::App& app, AnalyzeArgs& args);
/// `chimera analyze FILE [--config NAME] [--wcet-from PROFILE] [--overhead DURATION]`; returns the exit code.
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
};
/// `chimera modules [NAME]`; returns the exit code.
int modules_command(const ModulesArgs& args);

}  // namespace chimera::cli
