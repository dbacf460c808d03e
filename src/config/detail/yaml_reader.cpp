#include "detail/yaml_reader.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/config/loader.hpp"
#include "detail/name_index.hpp"

namespace chimera::config_detail {
namespace {

std::string join_path(std::string_view path, std::string_view key) {
  return path.empty() ? std::string(key) : fmt::format("{}.{}", path, key);
}

int line_of(const YAML::Node& node, int fallback) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? fallback : mark.line + 1;
}

// A value's line: a scalar where it is written, anything else (an empty value, a block list or
// mapping, whose mark is its first entry on a later line) at its key.
int value_line(const YAML::Node& value, int key_line) { return value.IsScalar() ? line_of(value, key_line) : key_line; }

bool is_plain(const YAML::Node& node) { return node.IsScalar() && node.Tag() == "?"; }

}  // namespace

Error Source::fail(int line, std::string_view path, std::string_view problem) const {
  if (path.empty()) return make_error(Errc::kInvalidInput, fmt::format("{}:{}: {}", file_, line, problem));
  return make_error(Errc::kInvalidInput, fmt::format("{}:{}: {}: {}", file_, line, path, problem));
}

Field element(const Field& sequence, std::size_t index, const YAML::Node& node) {
  return Field{node, line_of(node, sequence.line), fmt::format("{}[{}]", sequence.path, index)};
}

Result<MapReader> MapReader::create(const Source& source, const Field& field, std::string_view what,
                                    std::initializer_list<std::string_view> known) {
  if (!field.node.IsMap())
    return source.fail(field, fmt::format("{} must be a mapping of keys, not {}", what, describe(field.node)));
  std::vector<std::pair<std::string, int>> seen;
  for (const auto& kv : field.node) {
    const int key_line = line_of(kv.first, field.line);
    if (!kv.first.IsScalar()) return source.fail(key_line, field.path, "keys must be plain names");
    const std::string& key = kv.first.Scalar();
    const std::string path = join_path(field.path, key);
    if (std::find(known.begin(), known.end(), key) == known.end())
      return source.fail(key_line, path,
                         fmt::format("unknown key (known: {})", fmt::join(known.begin(), known.end(), ", ")));
    for (const auto& [name, line] : seen)
      if (name == key) return source.fail(key_line, path, fmt::format("written twice (first at line {})", line));
    seen.emplace_back(key, key_line);
  }
  return MapReader(field);
}

std::optional<Field> MapReader::get(std::string_view key) const {
  for (const auto& kv : field_.node) {
    if (kv.first.Scalar() != key) continue;
    const int key_line = line_of(kv.first, field_.line);
    return Field{kv.second, value_line(kv.second, key_line), join_path(field_.path, key)};
  }
  return std::nullopt;
}

Result<Field> MapReader::require(const Source& source, std::string_view key, std::string_view hint) const {
  if (auto f = get(key)) return *std::move(f);
  return source.fail(field_.line, join_path(field_.path, key), fmt::format("missing ({})", hint));
}

std::vector<std::pair<Field, std::string>> entries(const Field& map) {
  std::vector<std::pair<Field, std::string>> out;
  if (!map.node.IsMap()) return out;
  for (const auto& kv : map.node) {
    const int key_line = line_of(kv.first, map.line);
    const std::string& key = kv.first.Scalar();
    out.emplace_back(Field{kv.second, value_line(kv.second, key_line), join_path(map.path, key)}, key);
  }
  return out;
}

Result<void> check_free_keys(const Source& source, const Field& field, std::string_view what) {
  if (field.node.IsNull()) return {};
  if (!field.node.IsMap())
    return source.fail(field, fmt::format("{} must be a mapping, not {}", what, describe(field.node)));
  NameIndex seen;  // these maps are the file's to size (constants, configurations): no scan per key
  for (const auto& kv : field.node) {
    const int key_line = line_of(kv.first, field.line);
    if (!kv.first.IsScalar()) return source.fail(key_line, field.path, "keys must be plain names");
    const std::string& key = kv.first.Scalar();
    if (const auto line = seen.insert(key, key_line))
      return source.fail(key_line, join_path(field.path, key), fmt::format("written twice (first at line {})", *line));
  }
  return {};
}

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return fmt::format("\"{}\"", node.Scalar());
  if (node.IsSequence()) return "a list";
  return "a mapping";
}

std::optional<double> as_number(const YAML::Node& node) {
  if (!is_plain(node)) return std::nullopt;
  std::string_view text = node.Scalar();
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<bool> as_bool(const YAML::Node& node) {
  if (!is_plain(node)) return std::nullopt;
  const std::string& s = node.Scalar();
  if (s == "true" || s == "True" || s == "TRUE") return true;
  if (s == "false" || s == "False" || s == "FALSE") return false;
  return std::nullopt;
}

Result<std::string> read_text(const Source& source, const Field& field) {
  if (!field.node.IsScalar() || field.node.Scalar().empty())
    return source.fail(field, fmt::format("needs a text value, not {}", describe(field.node)));
  return field.node.Scalar();
}

Result<std::string> read_identifier(const Source& source, const Field& field, std::string_view what) {
  auto text = read_text(source, field);
  if (!text) return text.error();
  if (!is_identifier(*text))
    return source.fail(
        field, fmt::format("\"{}\" is not a valid {} (letters, digits and _, not starting with a digit)", *text, what));
  return text;
}

Result<std::string> read_variable_name(const Source& source, const Field& field) {
  auto name = read_identifier(source, field, "variable name");
  if (!name) return name.error();
  if (auto ok = check_variable_name_length(source, field, *name); !ok) return ok.error();
  return name;
}

Result<void> check_variable_name_length(const Source& source, const Field& field, std::string_view name) {
  if (name.size() > kMaxVariableName)
    return source.fail(field, fmt::format("variable name \"{}\" is longer than {} characters (the state variable "
                                          "table's limit)",
                                          name, kMaxVariableName));
  return {};
}

Result<std::string> read_process_name(const Source& source, const Field& field) {
  auto name = read_identifier(source, field, "process name");
  if (!name) return name.error();
  // It travels on a worker's command line and into its messages: keep it short.
  if (name->size() > kMaxProcessName)
    return source.fail(field, fmt::format("\"{}\" is longer than {} characters", *name, kMaxProcessName));
  return name;
}

Result<double> read_number(const Source& source, const Field& field) {
  if (auto v = as_number(field.node)) return *v;
  return source.fail(field, fmt::format("{} is not a number", describe(field.node)));
}

Result<int> read_index(const Source& source, const Field& field) {
  const auto v = as_number(field.node);
  if (!v || *v < 0 || *v > INT_MAX || std::floor(*v) != *v)
    return source.fail(field, fmt::format("{} is not a CPU number (a whole number >= 0)", describe(field.node)));
  return static_cast<int>(*v);
}

Result<std::int64_t> read_duration(const Source& source, const Field& field) {
  if (!field.node.IsScalar())
    return source.fail(field,
                       fmt::format("{} is not a duration (use ns, us, ms or s, e.g. 10ms)", describe(field.node)));
  auto ns = parse_duration_ns(field.node.Scalar());
  if (!ns) return source.fail(field, ns.error().message);
  return ns;
}

Result<std::int64_t> read_frequency_period(const Source& source, const Field& field) {
  if (!field.node.IsScalar())
    return source.fail(field, fmt::format("{} is not a frequency (use Hz or kHz, e.g. 100Hz)", describe(field.node)));
  auto ns = parse_frequency_period_ns(field.node.Scalar());
  if (!ns) return source.fail(field, ns.error().message);
  return ns;
}

Result<std::vector<double>> read_numbers(const Source& source, const Field& field) {
  if (auto v = as_number(field.node)) return std::vector<double>{*v};
  if (!field.node.IsSequence() || field.node.size() == 0)
    return source.fail(field, fmt::format("{} is not a number or a list of numbers", describe(field.node)));
  std::vector<double> out;
  for (std::size_t i = 0; i < field.node.size(); ++i) {
    auto v = read_number(source, element(field, i, field.node[i]));
    if (!v) return v.error();
    out.push_back(*v);
  }
  return out;
}

namespace {

// Every entry a scalar that is not a plain number: a number among text is more likely a mistake
// than a name, and quoting it ("3") says it is text.
Result<ParamValue> read_string_list(const Source& source, const Field& field) {
  StringList list;
  for (std::size_t i = 0; i < field.node.size(); ++i) {
    const Field e = element(field, i, field.node[i]);
    if (!e.node.IsScalar() || e.node.Scalar().empty())
      return source.fail(e,
                         fmt::format("{} is not text, but the list holds text (a list of strings)", describe(e.node)));
    if (as_number(e.node))
      return source.fail(
          e, fmt::format("{} is a number, but the list holds text (quote it to make it text)", describe(e.node)));
    list.push_back(e.node.Scalar());
  }
  return ParamValue{std::move(list)};
}

}  // namespace

Result<ParamValue> read_param_value(const Source& source, const Field& field) {
  const YAML::Node& node = field.node;
  if (node.IsNull()) return source.fail(field, "needs a value");
  if (node.IsMap())
    return source.fail(field, "a mapping is not a parameter value (use a number, true/false, text or a list)");
  if (node.IsScalar()) {
    if (auto v = as_number(node)) return ParamValue{*v};
    if (auto b = as_bool(node)) return ParamValue{*b};
    return ParamValue{node.Scalar()};
  }
  // A list: of numbers (a vector), of lists of numbers (a matrix) or of text (a list of strings),
  // decided by its first entry.
  if (node.size() == 0) return ParamValue{Vector{}};
  if (node[0].IsScalar() && !as_number(node[0])) return read_string_list(source, field);
  if (!node[0].IsSequence()) {
    Vector v;
    for (std::size_t i = 0; i < node.size(); ++i) {
      auto x = read_number(source, element(field, i, node[i]));
      if (!x) return x.error();
      v.push_back(*x);
    }
    return ParamValue{std::move(v)};
  }
  Matrix m;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const Field row = element(field, i, node[i]);
    if (!row.node.IsSequence())
      return source.fail(row,
                         fmt::format("{} is not a row (a matrix is a list of lists of numbers)", describe(row.node)));
    auto numbers = row.node.size() == 0 ? Result<std::vector<double>>(Vector{}) : read_numbers(source, row);
    if (!numbers) return numbers.error();
    m.push_back(*std::move(numbers));
  }
  return ParamValue{std::move(m)};
}

}  // namespace chimera::config_detail
