#include "load_file.hpp"

#include <cstdio>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/plugins.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::cli {

std::optional<SubsystemSpec> load_file(const std::string& file, const std::optional<std::string>& config) {
  // The file's module libraries first: its tasks may use their modules.
  if (auto plugins = load_file_plugins(file); !plugins) {
    fmt::print(stderr, "{}\n", plugins.error().message);
    return std::nullopt;
  }
  auto spec = load_subsystem_file(file, Registry::global());
  if (!spec) {
    fmt::print(stderr, "{}\n", spec.error().message);
    return std::nullopt;
  }
  if (config && spec->find_configuration(*config) == nullptr) {
    fmt::print(stderr, "{}: unknown configuration '{}'\n", file, *config);
    return std::nullopt;
  }
  return std::move(*spec);
}

}  // namespace chimera::cli
