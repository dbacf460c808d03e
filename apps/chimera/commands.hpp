#pragma once
// The subcommands of the chimera command, one file each; main.cpp only parses the command line.

#include <cstdint>
#include <optional>
#include <string>

#include "chimera/exec/subsystem.hpp"

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

struct ModulesArgs {
  std::optional<std::string> name;
};
/// `chimera modules [NAME]`; returns the exit code.
int modules_command(const ModulesArgs& args);

}  // namespace chimera::cli
