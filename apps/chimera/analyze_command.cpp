// chimera analyze FILE [--config NAME] [--wcet-from PROFILE] [--overhead DURATION] [--json]:
// schedulability per CPU under the file's scheduler (contract sections 2 and 4, docs/scheduling.md).

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "chimera/analysis/cpu_assignment.hpp"
#include "chimera/analysis/report.hpp"
#include "chimera/analysis/report_json.hpp"
#include "chimera/analysis/schedulability.hpp"
#include "chimera/analysis/task_models.hpp"
#include "chimera/analysis/wcet_profile.hpp"
#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "chimera/control/timing_table.hpp"
#include "chimera/core/duration_text.hpp"
#include "chimera/module/registry.hpp"
#include "chimera/svt/global_table.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "load_file.hpp"
#include "measure.hpp"
#include "stop_request.hpp"

namespace chimera::cli {
namespace {

using analysis::TaskModel;
using analysis::WcetProfile;

// Whether analysis needs a C that neither the file nor the profile gives. A task whose C would
// be its virtual_exec: is run too: on the virtual clock its module may charge more time.
bool needs_measuring(const std::vector<TaskModel>& models) {
  return std::any_of(models.begin(), models.end(), [](const TaskModel& m) {
    return !analysis::is_background(m) &&
           (m.wcet_source == analysis::WcetSource::kUnknown || m.wcet_source == analysis::WcetSource::kVirtual);
  });
}

// The line that says how the measured C were found: simulated time where a task has some, the
// host's time x the margin for the others.
std::string measured_note(const WcetProfile& measured, std::int64_t length) {
  const auto simulated = std::count_if(measured.tasks.begin(), measured.tasks.end(),
                                       [](const analysis::ProfileEntry& e) { return e.simulated; });
  const auto runs = fmt::format("the least of {} runs of {} on the virtual clock", kMeasureRuns, format_period(length));
  if (simulated == 0)
    return fmt::format("measured: C = {} x the longest cycle, {} (chimera profile and --wcet-from give better figures)",
                       analysis::kMeasuredMargin, runs);
  if (static_cast<std::size_t>(simulated) == measured.tasks.size())
    return fmt::format(
        "measured: C = the longest cycle's simulated time (virtual_exec plus what the module charged), {}", runs);
  return fmt::format(
      "measured: C = the longest cycle's simulated time (virtual_exec plus what the module charged) where a task has "
      "one, else {} x its longest cycle on the host, {}",
      analysis::kMeasuredMargin, runs);
}

// Prints the violations of the configurations to analyse; true when there are none.
bool legal(const SubsystemSpec& spec, const Resolution& resolution, const std::optional<std::string>& config) {
  const auto violations = verify_subsystem(resolution, config);
  for (const auto& v : violations) fmt::print(stderr, "{}: {}\n", spec.file, v.message);
  if (violations.empty()) return true;
  fmt::print(stderr, "{}: only legal configurations can be analysed (chimera verify says more)\n", spec.file);
  return false;
}

// nullopt: the configuration could not be analysed (the message is printed on stderr).
std::optional<analysis::AnalysedConfiguration> analyse_one(const SubsystemSpec& spec,
                                                           const analysis::ReleaseOrder& order,
                                                           const ConfigurationSpec& config, const WcetProfile* profile,
                                                           const analysis::AnalysisOptions& options) {
  // The CPUs come from what `chimera run` knows too (the file's wcet: and cpu:, its chains), so
  // that the assignment shown is the one a run makes; profile and measurements only refine the
  // analysis.
  const auto cpus = analysis::allowed_cpus(spec, static_cast<int>(::sysconf(_SC_NPROCESSORS_ONLN)));
  const auto file_cpu = analysis::assign_subsystem_cpus(spec, order, cpus, options);

  std::optional<WcetProfile> measured;
  std::string note;
  if (needs_measuring(analysis::task_models(spec, config.tasks, profile))) {
    const std::int64_t length = measurement_length_ns(spec, config.name);
    // Simulated time is what the virtual clock will charge, exactly: no margin on it.
    auto run =
        measure_profile(spec, config.name, ClockKind::kVirtual, length, kMeasureRuns, analysis::kMeasuredMargin, 1.0);
    if (!run) {
      // A refusal that points into the file (a module's init) leads with its file:line, as run's does.
      const std::string& why = run.error().message;
      if (why.starts_with(spec.file + ":"))
        fmt::print(stderr, "{} (configuration '{}', run to measure its execution times)\n", why, config.name);
      else
        fmt::print(stderr, "{}: configuration '{}': cannot run it to measure execution times: {}\n", spec.file,
                   config.name, why);
      return std::nullopt;
    }
    measured = *std::move(run);
    note = measured_note(*measured, length);
  }
  const auto models = analysis::task_models(spec, config.tasks, profile, measured ? &*measured : nullptr, &order);
  std::vector<int> cpu_of;
  cpu_of.reserve(models.size());
  for (const auto& m : models) cpu_of.push_back(file_cpu[static_cast<std::size_t>(m.file_index)]);
  auto result = analysis::analyse_configuration(models, cpu_of, cpus, spec.scheduler, options);
  return analysis::AnalysedConfiguration{
      analysis::ReportContext{spec.file, config.name, spec.scheduler, options, std::move(note)}, models,
      std::move(result)};
}

}  // namespace

CLI::App* add_analyze_command(CLI::App& app, AnalyzeArgs& args) {
  auto* cmd = app.add_subcommand("analyze", "Schedulability per CPU under the file's scheduler");
  cmd->add_option("FILE", args.file, "subsystem file (YAML)")->required();
  cmd->add_option_function<std::string>(
      "--config", [&args](const std::string& name) { args.config = name; }, "analyse only this configuration");
  cmd->add_option_function<std::string>(
      "--wcet-from", [&args](const std::string& path) { args.wcet_from = path; },
      "execution budgets from this profile (written by chimera profile)");
  cmd->add_option_function<std::string>(
      "--overhead",
      [&args](const std::string& text) {
        auto ns = parse_duration_ns(text);
        if (!ns) throw CLI::ValidationError("--overhead", ns.error().message);
        args.overhead_ns = *ns;
      },
      "framework overhead added to every C, per cycle (default 1us)");
  cmd->add_flag("--json", args.json, "print the analysis as one JSON document (docs/scheduling.md)");
  return cmd;
}

int analyze_command(const AnalyzeArgs& args) {
  auto spec = load_file(args.file, args.config);
  if (!spec) return kExitInvalid;
  std::optional<WcetProfile> profile;
  if (args.wcet_from) {
    auto read = analysis::read_wcet_profile_file(*args.wcet_from);
    if (read) {
      if (auto matches = analysis::check_profile_matches(*read, *spec); !matches) read = matches.error();
    }
    if (!read) {
      fmt::print(stderr, "{}\n", read.error().message);
      return kExitInvalid;
    }
    profile = *std::move(read);
  }
  const Resolution resolution = resolve_subsystem(*spec, Registry::global());
  if (!legal(*spec, resolution, args.config)) return kExitInvalid;
  // A signal ends a measuring run cleanly, its shared memory removed; the regions of an earlier
  // analyze that was killed outright (its pid in their names, so never made again) go now.
  install_stop_handlers();
  if (const std::size_t stale = GlobalTable::reclaim_stale(spec->name + "_measure_"); stale > 0)
    fmt::print(stderr, "removed {} shared memory region{} left by an earlier chimera analyze\n", stale,
               stale == 1 ? "" : "s");
  const analysis::ReleaseOrder order = analysis::compute_release_order(resolution.subsystem);

  const analysis::AnalysisOptions options{.overhead_ns = args.overhead_ns};
  // JSON is printed whole at the end, so that stdout holds one complete document or, when a
  // configuration cannot be analysed, nothing; the text goes out as each configuration is done.
  std::vector<analysis::AnalysedConfiguration> results;
  std::size_t infeasible = 0;
  for (const auto& config : spec->configurations) {
    if (args.config && config.name != *args.config) continue;
    auto a = analyse_one(*spec, order, config, profile ? &*profile : nullptr, options);
    if (!a) return kExitInvalid;
    infeasible += a->result.feasible ? 0 : 1;
    if (!args.json) {
      if (!results.empty()) std::fputs("\n", stdout);
      std::fputs(analysis::format_report(a->context, a->tasks, a->result).c_str(), stdout);
    }
    results.push_back(*std::move(a));
  }
  const std::size_t analysed = results.size();
  if (args.json) {
    std::fputs(analysis::analysis_json(args.file, results).c_str(), stdout);
    return infeasible == 0 ? kExitOk : kExitFailed;
  }
  if (infeasible == 0) {
    fmt::print("{}: {} configuration{} feasible\n", args.file, analysed, analysed == 1 ? "" : "s");
    return kExitOk;
  }
  fmt::print("{}: {} of {} configuration{} not feasible\n", args.file, infeasible, analysed, analysed == 1 ? "" : "s");
  return kExitFailed;
}

}  // namespace chimera::cli
