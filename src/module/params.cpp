#include "chimera/module/params.hpp"

#include <fmt/format.h>

namespace chimera {

std::string_view param_type_name(ParamType t) {
  switch (t) {
    case ParamType::kNumber: return "number";
    case ParamType::kBool: return "bool";
    case ParamType::kString: return "string";
    case ParamType::kVector: return "list of numbers";
    case ParamType::kMatrix: return "list of lists of numbers";
    case ParamType::kStringList: return "list of strings";
  }
  return "?";
}

ParamType param_type_of(const ParamValue& v) { return static_cast<ParamType>(v.index()); }

namespace {
std::string join_numbers(const Vector& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += fmt::format("{}{}", i != 0 ? ", " : "", v[i]);
  return out + "]";
}
}  // namespace

std::string to_string(const ParamValue& v) {
  switch (param_type_of(v)) {
    case ParamType::kNumber: return fmt::format("{}", std::get<double>(v));
    case ParamType::kBool: return std::get<bool>(v) ? "true" : "false";
    case ParamType::kString: return fmt::format("\"{}\"", std::get<std::string>(v));
    case ParamType::kVector: return join_numbers(std::get<Vector>(v));
    case ParamType::kMatrix: {
      const auto& m = std::get<Matrix>(v);
      std::string out = "[";
      for (std::size_t i = 0; i < m.size(); ++i) out += (i != 0 ? ", " : "") + join_numbers(m[i]);
      return out + "]";
    }
    case ParamType::kStringList: {
      const auto& list = std::get<StringList>(v);
      std::string out = "[";
      for (std::size_t i = 0; i < list.size(); ++i) out += fmt::format("{}\"{}\"", i != 0 ? ", " : "", list[i]);
      return out + "]";
    }
  }
  return "?";
}

const ParamValue* Params::find(std::string_view name) const {
  auto it = values_.find(name);
  return it == values_.end() ? nullptr : &it->second;
}

namespace {
template <class T>
T get_or(const Params& p, std::string_view name, T fallback) {
  const ParamValue* v = p.find(name);
  if (v == nullptr) return fallback;
  if (const T* t = std::get_if<T>(v)) return *t;
  return fallback;
}
}  // namespace

double Params::number(std::string_view name, double fallback) const { return get_or(*this, name, fallback); }
bool Params::flag(std::string_view name, bool fallback) const { return get_or(*this, name, fallback); }
std::string Params::text(std::string_view name, std::string fallback) const {
  return get_or(*this, name, std::move(fallback));
}
Vector Params::vector(std::string_view name, Vector fallback) const { return get_or(*this, name, std::move(fallback)); }
Matrix Params::matrix(std::string_view name, Matrix fallback) const { return get_or(*this, name, std::move(fallback)); }
StringList Params::strings(std::string_view name, StringList fallback) const {
  return get_or(*this, name, std::move(fallback));
}

}  // namespace chimera
