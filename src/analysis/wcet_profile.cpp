// The profile file (include/chimera/analysis/wcet_profile.hpp). It is read with the subsystem
// file's YAML helpers, so that its messages look the same: "file:line: key: problem".

#include "chimera/analysis/wcet_profile.hpp"

#include <cerrno>
#include <cmath>
#include <fstream>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/core/duration_text.hpp"
#include "config/detail/file_text.hpp"
#include "config/detail/yaml_reader.hpp"

namespace chimera::analysis {
namespace {

using config_detail::Field;
using config_detail::MapReader;
using config_detail::Source;

Result<std::int64_t> read_positive_duration(const Source& source, const Field& field) {
  auto ns = config_detail::read_duration(source, field);
  if (ns && *ns <= 0) return source.fail(field, "must be greater than zero");
  return ns;
}

Result<std::uint64_t> read_count(const Source& source, const Field& field) {
  const auto v = config_detail::as_number(field.node);
  if (!v || *v < 0 || std::floor(*v) != *v || *v > 1e18)
    return source.fail(field,
                       fmt::format("{} is not a count (a whole number >= 0)", config_detail::describe(field.node)));
  return static_cast<std::uint64_t>(*v);
}

Result<ProfileEntry> read_entry(const Source& source, const Field& field, const std::string& task) {
  auto map = MapReader::create(source, field, "a task's figures", {"wcet", "exec_max", "exec_p99", "cycles"});
  if (!map) return map.error();
  ProfileEntry entry;
  entry.task = task;
  entry.line = field.line;
  auto wcet_field = map->require(source, "wcet", "the budget analysis uses, e.g. wcet: 35us");
  if (!wcet_field) return wcet_field.error();
  auto wcet = read_positive_duration(source, *wcet_field);
  if (!wcet) return wcet.error();
  entry.wcet_ns = *wcet;
  for (const auto& [key, target] :
       {std::pair{"exec_max", &entry.exec_max_ns}, std::pair{"exec_p99", &entry.exec_p99_ns}}) {
    if (const auto f = map->get(key)) {
      auto ns = config_detail::read_duration(source, *f);
      if (!ns) return ns.error();
      *target = *ns;
    }
  }
  if (const auto f = map->get("cycles")) {
    auto n = read_count(source, *f);
    if (!n) return n.error();
    entry.cycles = *n;
  }
  return entry;
}

Result<WcetProfile> read_profile(const Source& source, std::string_view text) {
  auto document = config_detail::load_first_document(source, text);
  if (!document) return document.error();
  if (document->second_line || !document->node.IsMap())
    return source.fail(1, "", "a profile is one mapping: subsystem:, clock: and tasks: (written by chimera profile)");
  const Field root{document->node, document->node.Mark().line + 1, ""};
  auto top = MapReader::create(source, root, "the profile", {"subsystem", "clock", "tasks"});
  if (!top) return top.error();

  WcetProfile profile;
  profile.file = source.file();
  auto name = top->require(source, "subsystem", "the subsystem the profile was measured on");
  if (!name) return name.error();
  auto subsystem = config_detail::read_text(source, *name);
  if (!subsystem) return subsystem.error();
  profile.subsystem = *std::move(subsystem);
  profile.subsystem_line = name->line;
  if (const auto f = top->get("clock")) {
    const std::string clock = f->node.IsScalar() ? f->node.Scalar() : std::string();
    if (clock != "real" && clock != "virtual")
      return source.fail(*f, fmt::format("{} is not a clock (use real or virtual)", config_detail::describe(f->node)));
    profile.clock = clock;
  }

  auto tasks = top->require(source, "tasks", "a mapping of task name to its figures");
  if (!tasks) return tasks.error();
  if (auto ok = config_detail::check_free_keys(source, *tasks, "tasks"); !ok) return ok.error();
  for (const auto& [value, task] : config_detail::entries(*tasks)) {
    if (!is_identifier(task)) return source.fail(value, "not a task name");
    auto entry = read_entry(source, value, task);
    if (!entry) return entry.error();
    profile.tasks.push_back(*std::move(entry));
  }
  return profile;
}

std::string optional_fields(const ProfileEntry& e) {
  std::string out;
  if (e.exec_max_ns) out += fmt::format(", exec_max: {}", exact_duration_text(*e.exec_max_ns, DurationStyle::kFile));
  if (e.exec_p99_ns) out += fmt::format(", exec_p99: {}", exact_duration_text(*e.exec_p99_ns, DurationStyle::kFile));
  if (e.cycles) out += fmt::format(", cycles: {}", *e.cycles);
  return out;
}

}  // namespace

ProfileEntry measured_entry(std::string task, std::int64_t exec_max_ns, std::uint64_t cycles, double margin,
                            std::optional<std::int64_t> exec_p99_ns) {
  ProfileEntry e;
  e.task = std::move(task);
  e.wcet_ns =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(static_cast<double>(exec_max_ns) * margin)));
  e.exec_max_ns = exec_max_ns;
  e.exec_p99_ns = exec_p99_ns;
  e.cycles = cycles;
  return e;
}

Result<WcetProfile> read_wcet_profile_text(std::string_view text, const std::string& file_name) {
  const Source source(file_name);
  try {
    return read_profile(source, text);
  } catch (const YAML::Exception& e) {
    return source.fail(e.mark.is_null() ? 1 : e.mark.line + 1, "", fmt::format("YAML error: {}", e.msg));
  }
}

Result<WcetProfile> read_wcet_profile_file(const std::string& path) {
  // As a subsystem file is read: a FIFO, a device or gigabytes are refused, never waited on.
  auto text = config_detail::read_file_text(path, "profile");
  if (!text) return text.error();
  return read_wcet_profile_text(*text, path);
}

std::string format_wcet_profile(const WcetProfile& profile) {
  std::string out = "# written by chimera profile: wcet is the budget chimera analyze --wcet-from uses\n";
  out += fmt::format("subsystem: {}\n", profile.subsystem);
  if (!profile.clock.empty()) out += fmt::format("clock: {}\n", profile.clock);
  if (profile.tasks.empty()) return out + "tasks: {}\n";
  out += "tasks:\n";
  for (const auto& e : profile.tasks)
    out += fmt::format("  {}: {{ wcet: {}{} }}\n", e.task, exact_duration_text(e.wcet_ns, DurationStyle::kFile),
                       optional_fields(e));
  return out;
}

Result<void> write_wcet_profile_file(const std::string& path, const WcetProfile& profile) {
  std::ofstream out(path, std::ios::trunc);
  if (!out)
    return make_error(Errc::kInvalidInput,
                      fmt::format("{}: cannot write the profile ({})", path, std::generic_category().message(errno)));
  out << format_wcet_profile(profile);
  out.close();
  if (!out) return make_error(Errc::kInvalidInput, fmt::format("{}: cannot write the profile", path));
  return {};
}

Result<void> check_profile_matches(const WcetProfile& profile, const SubsystemSpec& spec) {
  const Source source(profile.file);
  if (profile.subsystem != spec.name)
    return source.fail(profile.subsystem_line, "subsystem",
                       fmt::format("the profile is of subsystem {}, but {} describes subsystem {}", profile.subsystem,
                                   spec.file, spec.name));
  for (const auto& e : profile.tasks) {
    if (spec.find_task(e.task) != nullptr) continue;
    std::vector<std::string> names;
    for (const auto& t : spec.tasks) names.push_back(t.name);
    return source.fail(e.line, "tasks." + e.task,
                       fmt::format("no task named {} in {} (tasks: {})", e.task, spec.file, fmt::join(names, ", ")));
  }
  return {};
}

}  // namespace chimera::analysis
