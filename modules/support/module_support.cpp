#include "support/module_support.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <set>

namespace chimera::modules {

const char* intern(std::string message) {
  static std::mutex mutex;
  static std::set<std::string> texts;
  const std::lock_guard lock(mutex);
  return texts.insert(std::move(message)).first->c_str();
}

Vector per_joint(const Params& p, std::string_view name, Vector fallback, std::size_t n) {
  Vector v = p.vector(name, std::move(fallback));
  if (v.size() == 1) v.assign(n, v[0]);
  if (v.size() != n || !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); })) v.clear();
  return v;
}

bool all_non_negative(const Vector& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return x >= 0.0; });
}

}  // namespace chimera::modules
