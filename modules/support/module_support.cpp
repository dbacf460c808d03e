#include "support/module_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
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

std::string log_file_path(const std::string& file) {
  std::filesystem::path path = file;
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read in init; nothing in chimera changes the environment
  const char* dir = std::getenv("CHIMERA_LOG_DIR");
  if (path.is_relative() && dir != nullptr && *dir != '\0') path = std::filesystem::path(dir) / path;
  return path.string();
}

}  // namespace chimera::modules
