// chimera verify FILE [--config NAME]: rules 1 to 3 for every configuration (or one).

#include <algorithm>
#include <cstdio>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "chimera/module/registry.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "load_file.hpp"

namespace chimera::cli {

namespace {
// "processes: main (robot, pid), vision (vision)": which tasks share a fate (docs/processes.md).
std::string describe_processes(const SubsystemSpec& spec) {
  std::vector<std::pair<std::string, std::vector<std::string>>> groups{{std::string(kMainProcess), {}}};
  for (const auto& t : spec.tasks) {
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == t.process; });
    if (it == groups.end()) it = groups.insert(groups.end(), {t.process, {}});
    it->second.push_back(t.name);
  }
  std::string text = "processes:";
  for (const auto& [name, tasks] : groups)
    if (!tasks.empty()) text += fmt::format("{} {} ({})", text.back() == ':' ? "" : ",", name, fmt::join(tasks, ", "));
  return text;
}
}  // namespace

int verify_command(const VerifyArgs& args) {
  const Registry& registry = Registry::global();
  auto spec = load_file(args.file, args.config);
  if (!spec) return kExitInvalid;

  const Resolution resolution = resolve_subsystem(*spec, registry);
  const auto violations = verify_subsystem(resolution, args.config);
  const std::size_t checked = args.config ? 1 : spec->configurations.size();

  if (spec->uses_module_processes()) fmt::print("{}: {}\n", args.file, describe_processes(*spec));
  std::set<std::string> illegal;
  bool file_wide = false;
  for (const auto& v : violations) {
    fmt::print("{}: {}\n", args.file, v.message);
    if (v.configuration.empty())
      file_wide = true;
    else
      illegal.insert(v.configuration);
  }

  if (violations.empty()) {
    if (args.config)
      fmt::print("{}: configuration '{}' legal\n", args.file, *args.config);
    else
      fmt::print("{}: {} configuration{} legal\n", args.file, checked, checked == 1 ? "" : "s");
    return kExitOk;
  }
  // File-wide violations (configuration "") make every configuration unusable.
  const std::size_t bad = file_wide ? checked : illegal.size();
  fmt::print("{}: {} of {} configuration{} illegal, {} violation{}\n", args.file, bad, checked, checked == 1 ? "" : "s",
             violations.size(), violations.size() == 1 ? "" : "s");
  return kExitFailed;
}

}  // namespace chimera::cli
