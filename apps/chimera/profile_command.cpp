// chimera profile FILE [--config NAME] [--for DURATION] [--clock real|virtual] [--margin X] -o FILE:
// runs a configuration and writes the execution budgets it measured, a profile that
// `chimera analyze --wcet-from FILE` takes as each task's C (docs/scheduling.md).

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "chimera/analysis/wcet_profile.hpp"
#include "chimera/config/loader.hpp"
#include "chimera/control/timing_table.hpp"
#include "chimera/core/duration_text.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "load_file.hpp"
#include "measure.hpp"

namespace chimera::cli {

CLI::App* add_profile_command(CLI::App& app, ProfileArgs& args) {
  auto* cmd = app.add_subcommand("profile", "Run a configuration and write the execution budgets it measured");
  cmd->add_option("FILE", args.file, "subsystem file (YAML)")->required();
  cmd->add_option("-o,--output", args.output, "profile to write (YAML), for chimera analyze --wcet-from")->required();
  cmd->add_option_function<std::string>(
      "--config", [&args](const std::string& name) { args.config = name; },
      "configuration to run (default: the file's start)");
  cmd->add_option_function<std::string>(
      "--for",
      [&args](const std::string& text) {
        auto ns = parse_duration_ns(text);
        if (!ns) throw CLI::ValidationError("--for", ns.error().message);
        if (*ns <= 0) throw CLI::ValidationError("--for", "the duration must be positive");
        args.for_ns = *ns;
      },
      "how long to run (default 10s)");
  cmd->add_option("--clock", args.clock, "real (default: the machine's own times) or virtual")
      ->check(CLI::IsMember({"real", "virtual"}))
      ->capture_default_str();
  cmd->add_option("--margin", args.margin, "budget = longest cycle x this")
      ->check(CLI::Range(1.0, 100.0))
      ->capture_default_str();
  return cmd;
}

int profile_command(const ProfileArgs& args) {
  auto spec = load_file(args.file, args.config);
  if (!spec) return kExitInvalid;
  const std::string configuration = args.config.value_or(spec->start);
  const ClockKind clock = args.clock == "virtual" ? ClockKind::kVirtual : ClockKind::kReal;
  // One run: on the real clock every cycle's CPU time is measured (the thread's own clock, not
  // the wall clock, so preemption by other tasks is not counted as its execution).
  // On the virtual clock a task's cycle time is its simulated time where it has some.
  auto profile = measure_profile(*spec, configuration, clock, args.for_ns, 1, args.margin, args.margin);
  if (!profile) {
    fmt::print(stderr, "{}\n", profile.error().message);
    return kExitInvalid;
  }
  if (auto written = analysis::write_wcet_profile_file(args.output, *profile); !written) {
    fmt::print(stderr, "{}\n", written.error().message);
    return kExitInvalid;
  }
  fmt::print("{}: configuration '{}' ran {} on the {} clock; budgets = longest cycle x {}:\n", args.file, configuration,
             format_duration(args.for_ns), args.clock, args.margin);
  for (const auto& e : profile->tasks) {
    // Which clock the cycle times are in: on the virtual clock a task with no simulated time
    // (no virtual_exec:, its module charges none) is timed on the host.
    const char* in = clock == ClockKind::kReal ? ""
                     : e.simulated             ? ", simulated time"
                                               : ", host time: no simulated time";
    fmt::print("  {:<16} wcet {:>10}  (longest {}, p99 {}, {} cycles{})\n", e.task, format_duration(e.wcet_ns),
               format_duration(e.exec_max_ns.value_or(0)),
               e.exec_p99_ns ? format_duration(*e.exec_p99_ns) : std::string("-"), e.cycles.value_or(0), in);
  }
  fmt::print("written to {} (chimera analyze {} --wcet-from {})\n", args.output, args.file, args.output);
  return kExitOk;
}

}  // namespace chimera::cli
