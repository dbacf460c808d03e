#include "chimera/module/registry.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace chimera {

Registry& Registry::global() {
  static Registry registry;  // built on first use, so registrations in any order find it
  return registry;
}

Result<void> Registry::add(ModuleInfo info) {
  if (info.name.empty() || !info.declare || !info.make)
    return make_error(Errc::kInvalidInput, "a module needs a name, a declare function and a factory");
  if (find(info.name) != nullptr)
    return make_error(Errc::kInvalidInput, fmt::format("module '{}' is registered twice", info.name));
  modules_.push_back(std::make_unique<ModuleInfo>(std::move(info)));
  return {};
}

const ModuleInfo* Registry::find(std::string_view name) const {
  for (const auto& m : modules_)
    if (m->name == name) return m.get();
  return nullptr;
}

std::vector<const ModuleInfo*> Registry::list() const {
  std::vector<const ModuleInfo*> out;
  out.reserve(modules_.size());
  for (const auto& m : modules_) out.push_back(m.get());
  std::sort(out.begin(), out.end(), [](const ModuleInfo* a, const ModuleInfo* b) { return a->name < b->name; });
  return out;
}

}  // namespace chimera
