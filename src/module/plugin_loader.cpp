#include "chimera/module/plugin_loader.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/module/registry.hpp"
#include "detail/declaration_check.hpp"

namespace chimera {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kPathVariable = "CHIMERA_MODULE_PATH";

bool is_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

std::string absolute_path(const fs::path& p) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(fs::absolute(p, ec), ec);
  return ec ? p.string() : canonical.string();
}

// What a library brought, checked; on a problem its modules leave the registry again.
Result<LoadedPlugin> check_capture(std::string_view name, const std::string& path, const Registry::Capture& capture) {
  Registry& registry = Registry::global();
  std::string problem;
  if (!capture.refused.empty()) {
    problem = capture.refused.front();
  } else if (capture.added.empty()) {
    problem =
        "registers no modules (a module library registers each of its modules with CHIMERA_REGISTER_MODULE "
        "or CHIMERA_REGISTER_C_MODULE)";
  } else {
    for (const auto& module : capture.added) {
      if (auto ok = module_detail::check_module(*registry.find(module)); !ok) {
        problem = ok.error().message;
        break;
      }
    }
  }
  if (problem.empty()) return LoadedPlugin{path, capture.added};
  for (const auto& module : capture.added) registry.remove(module);
  return make_error(Errc::kInvalidInput, fmt::format("'{}' ({}): {}", name, path, problem));
}

}  // namespace

std::vector<std::string> module_search_path() {
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read before any thread that could change the environment
  const char* value = std::getenv(kPathVariable.data());
  std::vector<std::string> dirs;
  if (value == nullptr) return dirs;
  std::string_view rest(value);
  while (!rest.empty()) {
    const auto colon = rest.find(':');
    const std::string_view dir = rest.substr(0, colon);
    if (!dir.empty()) dirs.emplace_back(dir);
    if (colon == std::string_view::npos) break;
    rest.remove_prefix(colon + 1);
  }
  return dirs;
}

Result<std::string> find_plugin(std::string_view name, std::span<const std::string> search_path,
                                const std::string& base_dir) {
  if (name.find('/') != std::string_view::npos) {
    fs::path p(name);
    if (p.is_relative()) p = fs::path(base_dir) / p;
    if (is_file(p)) return absolute_path(p);
    return make_error(Errc::kNotFound, fmt::format("cannot find '{}' (no such file: {})", name, p.string()));
  }
  std::vector<std::string> candidates{std::string(name)};
  if (!name.ends_with(".so")) candidates.push_back(fmt::format("lib{}.so", name));
  for (const auto& dir : search_path)
    for (const auto& file : candidates)
      if (const fs::path p = fs::path(dir) / file; is_file(p)) return absolute_path(p);
  if (search_path.empty())
    return make_error(Errc::kNotFound,
                      fmt::format("cannot find '{}': {} is not set (a ':'-separated list of directories of module "
                                  "libraries), and the name is not a path",
                                  name, kPathVariable));
  return make_error(Errc::kNotFound, fmt::format("cannot find '{}' on {} ({})", name, kPathVariable,
                                                 fmt::join(search_path.begin(), search_path.end(), ":")));
}

Result<LoadedPlugin> load_plugin(std::string_view name, const std::string& path) {
  // A library's static initializers run once, at its first dlopen: a second load must not be
  // taken for a library without modules. Not thread-safe, like the registry.
  static std::map<std::string, Result<LoadedPlugin>, std::less<>> loaded;
  const std::string key = absolute_path(path);
  if (const auto it = loaded.find(key); it != loaded.end()) return it->second;

  Registry& registry = Registry::global();
  registry.begin_capture(key);
  // RTLD_NOW: a missing symbol fails here, with a message, not later inside a task's cycle.
  void* handle = ::dlopen(key.c_str(), RTLD_NOW | RTLD_LOCAL);
  const Registry::Capture capture = registry.end_capture();
  Result<LoadedPlugin> outcome = LoadedPlugin{};
  if (handle == nullptr) {
    const char* why = ::dlerror();  // NOLINT(concurrency-mt-unsafe): loading is single-threaded, see the header
    outcome = make_error(Errc::kInvalidInput,
                         fmt::format("cannot load '{}': {}", name, why != nullptr ? why : "dlopen failed"));
  } else {
    outcome = check_capture(name, key, capture);
  }
  // The handle is never closed: the registry's modules point into the library's code.
  loaded.emplace(key, outcome);
  return outcome;
}

std::vector<std::string> plugins_on_path(std::span<const std::string> search_path) {
  std::vector<std::string> files;
  for (const auto& dir : search_path) {
    std::error_code ec;
    std::vector<std::string> here;
    // A directory that cannot be read offers nothing; the increment's error form never throws.
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
      if (it->path().extension() == ".so" && is_file(it->path())) here.push_back(absolute_path(it->path()));
    std::sort(here.begin(), here.end());
    for (auto& file : here)
      if (std::find(files.begin(), files.end(), file) == files.end()) files.push_back(std::move(file));
  }
  return files;
}

}  // namespace chimera
