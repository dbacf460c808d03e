#include "detail/remote_loader.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace chimera::config_detail {

namespace {

// The largest DDS domain id: the RTPS port mapping (7400 + 250 * domain) must stay below 65536.
constexpr double kMaxDomain = 232;
// Far beyond any state variable; keeps a sample's size in range of the wire format's uint32.
constexpr double kMaxCount = 1U << 20;

Result<std::uint32_t> read_count(const Source& source, const Field& field) {
  const auto v = as_number(field.node);
  if (!v || *v < 1 || *v > kMaxCount || std::floor(*v) != *v)
    return source.fail(field, fmt::format("{} is not an element count (a whole number from 1 to {})",
                                          describe(field.node), static_cast<std::uint32_t>(kMaxCount)));
  return static_cast<std::uint32_t>(*v);
}

template <class Enum>
Result<Enum> read_choice(const Source& source, const Field& field, std::initializer_list<Enum> choices,
                         std::string_view (*name_of)(Enum)) {
  const std::string text = field.node.IsScalar() ? field.node.Scalar() : std::string();
  std::string names;
  for (Enum c : choices) {
    if (name_of(c) == text) return c;
    names += names.empty() ? "" : " or ";
    names += name_of(c);
  }
  return source.fail(field, fmt::format("{} is not one of {}", describe(field.node), names));
}

Result<ImportSpec> read_import(const Source& source, const Field& value, const std::string& name) {
  auto map = MapReader::create(source, value, "an import",
                               {"type", "count", "max_age", "reliability", "durability"});
  if (!map) return map.error();
  ImportSpec import;
  import.variable = name;
  import.loc = SourceLoc{source.file(), value.line};
  auto type = map->require(source, "type", "the element type, e.g. type: f64");
  if (!type) return type.error();
  const auto parsed = type->node.IsScalar() ? parse_elem_type(type->node.Scalar()) : std::nullopt;
  if (!parsed) return source.fail(*type, fmt::format("{} is not an element type", describe(type->node)));
  if (*parsed != ElemType::kF64)
    return source.fail(*type, fmt::format("{} cannot travel: imports are f64 (the wire format is "
                                          "std_msgs/msg/Float64MultiArray)",
                                          elem_name(*parsed)));
  import.type = *parsed;
  auto count = map->require(source, "count", "the element count, e.g. count: 6");
  if (!count) return count.error();
  auto n = read_count(source, *count);
  if (!n) return n.error();
  import.count = *n;
  auto age = map->require(source, "max_age", "how old the value may become before it is stale, e.g. max_age: 50ms");
  if (!age) return age.error();
  auto ns = read_duration(source, *age);
  if (!ns) return ns.error();
  if (*ns <= 0) return source.fail(*age, "must be longer than 0");
  import.max_age_ns = *ns;
  if (const auto f = map->get("reliability")) {
    auto r = read_choice(source, *f, {DdsReliability::kReliable, DdsReliability::kBestEffort}, reliability_name);
    if (!r) return r.error();
    import.reliability = *r;
  }
  if (const auto f = map->get("durability")) {
    auto d = read_choice(source, *f, {DdsDurability::kVolatile, DdsDurability::kTransientLocal}, durability_name);
    if (!d) return d.error();
    import.durability = *d;
  }
  return import;
}

}  // namespace

Result<void> read_exports(const Source& source, const std::optional<Field>& field, SubsystemSpec& spec) {
  if (!field || field->node.IsNull()) return {};
  if (!field->node.IsSequence())
    return source.fail(*field, fmt::format("must be a list of state variables, e.g. [x_m, theta_m], not {}",
                                           describe(field->node)));
  for (std::size_t i = 0; i < field->node.size(); ++i) {
    const Field e = element(*field, i, field->node[i]);
    auto name = read_identifier(source, e, "variable");
    if (!name) return name.error();
    const bool twice = std::any_of(spec.exports.begin(), spec.exports.end(),
                                   [&](const ExportSpec& x) { return x.variable == *name; });
    if (twice) return source.fail(e, fmt::format("{} is listed twice", *name));
    spec.exports.push_back(ExportSpec{*std::move(name), SourceLoc{source.file(), e.line}});
  }
  return {};
}

Result<void> read_imports(const Source& source, const std::optional<Field>& field, SubsystemSpec& spec) {
  if (!field || field->node.IsNull()) return {};
  if (auto ok = check_free_keys(source, *field, "imports"); !ok) return ok.error();
  for (const auto& entry : entries(*field)) {
    // Named, not bound: clang 14 (the fuzz tree's compiler) cannot capture a structured binding.
    const auto& value = entry.first;
    const auto& name = entry.second;
    if (!is_identifier(name))
      return source.fail(value, "not a valid variable name (letters, digits and _, not starting with a digit)");
    if (auto ok = check_variable_name_length(source, value, name); !ok) return ok.error();
    const bool exported = std::any_of(spec.exports.begin(), spec.exports.end(),
                                      [&](const ExportSpec& x) { return x.variable == name; });
    if (exported)
      return source.fail(value, fmt::format("{} is exported too; a subsystem either publishes a variable or reads it "
                                            "from another",
                                            name));
    auto import = read_import(source, value, name);
    if (!import) return import.error();
    spec.imports.push_back(*std::move(import));
  }
  return {};
}

Result<void> read_dds(const Source& source, const std::optional<Field>& field, SubsystemSpec& spec) {
  if (!field) return {};
  auto map = MapReader::create(source, *field, "dds", {"domain", "partition"});
  if (!map) return map.error();
  spec.dds.loc = SourceLoc{source.file(), field->line};
  if (const auto f = map->get("domain")) {
    const auto v = as_number(f->node);
    if (!v || *v < 0 || *v > kMaxDomain || std::floor(*v) != *v)
      return source.fail(*f, fmt::format("{} is not a DDS domain id (a whole number from 0 to {})",
                                         describe(f->node), static_cast<int>(kMaxDomain)));
    spec.dds.domain = static_cast<std::uint32_t>(*v);
  }
  if (const auto f = map->get("partition"); f && !(f->node.IsScalar() && f->node.Scalar().empty())) {
    auto text = read_text(source, *f);
    if (!text) return text.error();
    // DDS reads these characters as a pattern that matches other partitions.
    if (text->find_first_of("*?[]\\") != std::string::npos)
      return source.fail(*f, fmt::format("\"{}\" holds a wildcard character (* ? [ ] \\); name one partition", *text));
    spec.dds.partition = *std::move(text);
  }
  return {};
}

}  // namespace chimera::config_detail
