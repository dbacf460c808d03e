#include "chimera/config/plugins.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"

namespace chimera {

Result<std::vector<LoadedPlugin>> load_file_plugins(const std::string& path) {
  auto refs = read_plugin_names_file(path);
  if (!refs) return refs.error();
  std::vector<LoadedPlugin> loaded;
  if (refs->empty()) return loaded;
  const std::vector<std::string> search_path = module_search_path();
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  const std::string base_dir = parent.empty() ? std::string(".") : parent.string();
  for (const PluginRef& ref : *refs) {
    auto found = find_plugin(ref.name, search_path, base_dir);
    auto plugin = found ? load_plugin(ref.name, *found) : Result<LoadedPlugin>(found.error());
    if (!plugin)
      return make_error(Errc::kInvalidInput,
                        fmt::format("{}:{}: {}: {}", path, ref.line, ref.key, plugin.error().message));
    loaded.push_back(*std::move(plugin));
  }
  return loaded;
}

}  // namespace chimera
