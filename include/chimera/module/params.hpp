#pragma once
// A module's in-consts from the subsystem file's `params:` (numbers, flags, text, vectors,
// matrices, lists of text), checked against the module's declared parameters when the file is loaded.

#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace chimera {

enum class ParamType { kNumber, kBool, kString, kVector, kMatrix, kStringList };

std::string_view param_type_name(ParamType t);

using Vector = std::vector<double>;
using Matrix = std::vector<std::vector<double>>;
using StringList = std::vector<std::string>;
/// The alternatives are in ParamType's order.
using ParamValue = std::variant<double, bool, std::string, Vector, Matrix, StringList>;

ParamType param_type_of(const ParamValue& v);
/// "0.5", "true", "\"text\"", "[1, 2]", "[[1, 2], [3]]", "[\"a\", \"b\"]".
std::string to_string(const ParamValue& v);

/// Parameter values by name. Getters return the fallback when the name is absent or holds
/// another type (the loader has already rejected wrong types for declared parameters).
/// Not real-time safe: read them in init.
class Params {
 public:
  void set(std::string name, ParamValue value) { values_[std::move(name)] = std::move(value); }
  [[nodiscard]] bool has(std::string_view name) const { return values_.find(name) != values_.end(); }
  [[nodiscard]] const ParamValue* find(std::string_view name) const;

  [[nodiscard]] double number(std::string_view name, double fallback = 0.0) const;
  [[nodiscard]] bool flag(std::string_view name, bool fallback = false) const;
  [[nodiscard]] std::string text(std::string_view name, std::string fallback = {}) const;
  [[nodiscard]] Vector vector(std::string_view name, Vector fallback = {}) const;
  [[nodiscard]] Matrix matrix(std::string_view name, Matrix fallback = {}) const;
  [[nodiscard]] StringList strings(std::string_view name, StringList fallback = {}) const;

  [[nodiscard]] const std::map<std::string, ParamValue, std::less<>>& all() const { return values_; }

 private:
  std::map<std::string, ParamValue, std::less<>> values_;
};

}  // namespace chimera
