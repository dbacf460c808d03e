#pragma once
// Helpers shared by the subsystem file loader: where a value was written, reading typed values
// out of yaml-cpp nodes, and building "file:line: key: problem" errors. Private to src/config.

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "chimera/core/identifier.hpp"
#include "chimera/core/result.hpp"
#include "chimera/module/params.hpp"

namespace chimera::config_detail {

/// One value of the file together with where it sits, so any problem with it can be reported.
struct Field {
  YAML::Node node;
  int line = 0;      // 1-based; an empty value takes the line of its key
  std::string path;  // "tasks[2].period"
};

/// The file being read: every error names it.
class Source {
 public:
  explicit Source(std::string file) : file_(std::move(file)) {}

  [[nodiscard]] const std::string& file() const { return file_; }
  /// "file:line: path: problem" (the path is left out when empty).
  [[nodiscard]] Error fail(int line, std::string_view path, std::string_view problem) const;
  [[nodiscard]] Error fail(const Field& field, std::string_view problem) const {
    return fail(field.line, field.path, problem);
  }

 private:
  std::string file_;
};

/// The element `index` of a sequence field, with its own line and path "path[index]".
Field element(const Field& sequence, std::size_t index, const YAML::Node& node);

/// A mapping whose keys have been checked: every key is a known, unrepeated scalar.
class MapReader {
 public:
  /// Fails on a field that is not a mapping, an unknown key (listing the known ones) or a key
  /// written twice. `what` names the mapping in the "must be a mapping" message.
  static Result<MapReader> create(const Source& source, const Field& field, std::string_view what,
                                  std::initializer_list<std::string_view> known);

  /// The value of `key`, or nullopt when the key is absent.
  [[nodiscard]] std::optional<Field> get(std::string_view key) const;
  /// The value of `key`; when absent, fails with "path.key: missing (hint)".
  [[nodiscard]] Result<Field> require(const Source& source, std::string_view key, std::string_view hint) const;
  [[nodiscard]] const Field& field() const { return field_; }

 private:
  explicit MapReader(Field field) : field_(std::move(field)) {}
  Field field_;
};

/// Every entry of a mapping in file order; keys are returned as text (the map was checked with
/// check_free_keys or MapReader first).
std::vector<std::pair<Field, std::string>> entries(const Field& map);
/// For mappings with user-chosen keys (params, rename, constants, configurations): fails on a
/// non-mapping (an empty value counts as an empty mapping), a non-scalar or repeated key.
Result<void> check_free_keys(const Source& source, const Field& field, std::string_view what);

/// How a value reads in messages: "\"10 ms\"", "a list", "a mapping", "nothing".
std::string describe(const YAML::Node& node);
/// Plain (unquoted, untagged) scalars only: quoting a number makes it text.
std::optional<double> as_number(const YAML::Node& node);
std::optional<bool> as_bool(const YAML::Node& node);

Result<std::string> read_text(const Source& source, const Field& field);
Result<std::string> read_identifier(const Source& source, const Field& field, std::string_view what);
/// A state variable's name: an identifier of at most kMaxVariableName characters.
Result<std::string> read_variable_name(const Source& source, const Field& field);
/// Fails, at `field`, on a variable name longer than kMaxVariableName (for names read as keys).
Result<void> check_variable_name_length(const Source& source, const Field& field, std::string_view name);
/// A `process:` name (docs/processes.md): an identifier of at most kMaxProcessName characters.
Result<std::string> read_process_name(const Source& source, const Field& field);
inline constexpr std::size_t kMaxProcessName = 40;
Result<double> read_number(const Source& source, const Field& field);
/// A whole number >= 0 (CPU indices).
Result<int> read_index(const Source& source, const Field& field);
Result<std::int64_t> read_duration(const Source& source, const Field& field);
Result<std::int64_t> read_frequency_period(const Source& source, const Field& field);
/// A number or a non-empty list of numbers (`constants:` values).
Result<std::vector<double>> read_numbers(const Source& source, const Field& field);
/// A parameter value: number, bool, text, list of numbers, list of lists of numbers, or list of
/// text.
Result<ParamValue> read_param_value(const Source& source, const Field& field);

/// The first YAML document of a text, and where a second one starts (1-based line), if any.
struct FirstDocument {
  YAML::Node node;  // null if the text holds no document
  std::optional<int> second_line;
};

/// The first document of `text` and whether another follows, in place of YAML::LoadAll, which in
/// yaml-cpp 0.7 loops for ever, taking memory as it goes, on a ',' outside brackets
/// (jbeder/yaml-cpp#1040, fixed upstream by #1319): the parser, stuck on a token it cannot use,
/// starts empty documents there without end. That, and any syntax error, is
/// "file:line: YAML syntax error: ...". Not real-time safe (yaml_documents.cpp).
Result<FirstDocument> load_first_document(const Source& source, std::string_view text);

}  // namespace chimera::config_detail
