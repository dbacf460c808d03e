#include "detail/request_loader.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace chimera::config_detail {

namespace {

Result<std::string> read_configuration_name(const Source& source, const Field& field, const FileNames& file_names,
                                            const SubsystemSpec& spec) {
  auto name = read_text(source, field);
  if (!name) return name.error();
  if (file_names.configurations.contains(*name)) return name;
  std::vector<std::string> names;
  for (const auto& c : spec.configurations) names.push_back(c.name);
  return source.fail(field,
                     fmt::format("no configuration named {} (configurations: {})", *name, fmt::join(names, ", ")));
}

}  // namespace

Result<void> read_requests(const Source& source, const std::optional<Field>& field, const FileNames& names,
                           SubsystemSpec& spec) {
  if (!field || field->node.IsNull()) return {};
  if (!field->node.IsSequence())
    return source.fail(*field, fmt::format("must be a list of switches tasks may ask for, e.g. "
                                           "[{{from: standard, to: near_singularity, by: monitor}}], not {}",
                                           describe(field->node)));
  for (std::size_t i = 0; i < field->node.size(); ++i) {
    const Field entry = element(*field, i, field->node[i]);
    auto map = MapReader::create(source, entry, "a request", {"from", "to", "by"});
    if (!map) return map.error();
    SwitchRequestSpec request;
    request.loc = SourceLoc{source.file(), entry.line};
    auto to = map->require(source, "to", "the configuration a task may ask for");
    if (!to) return to.error();
    auto to_name = read_configuration_name(source, *to, names, spec);
    if (!to_name) return to_name.error();
    request.to = *std::move(to_name);
    if (const auto from = map->get("from")) {
      auto from_name = read_configuration_name(source, *from, names, spec);
      if (!from_name) return from_name.error();
      if (*from_name == request.to)
        return source.fail(*from, "a switch from a configuration to itself changes nothing");
      request.from = *std::move(from_name);
    }
    if (const auto by = map->get("by")) {
      auto task = read_text(source, *by);
      if (!task) return task.error();
      if (!names.tasks.contains(*task)) {
        std::vector<std::string> task_names;
        for (const auto& t : spec.tasks) task_names.push_back(t.name);
        return source.fail(*by, fmt::format("no task named {} (tasks: {})", *task, fmt::join(task_names, ", ")));
      }
      request.by = *std::move(task);
    }
    spec.requests.push_back(std::move(request));
  }
  return {};
}

}  // namespace chimera::config_detail
