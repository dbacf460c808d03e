#include "chimera/module/registry.hpp"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

extern "C" void chimera_register_cxx_module(const chimera_cxx_abi_stamp* stamp, const char* module, void (*add)()) {
  chimera::Registry& registry = chimera::Registry::global();
  const std::string_view name = module != nullptr ? std::string_view(module) : std::string_view("?");
  if (stamp == nullptr || stamp->magic != chimera::kCxxAbiStampMagic) {
    registry.refuse(
        fmt::format("module {} carries no ABI stamp: it was not built with this Chimera's "
                    "CHIMERA_REGISTER_MODULE; rebuild it against Chimera {}",
                    name, chimera::kChimeraVersion));
    return;
  }
  if (stamp->fingerprint != chimera::kModuleAbiFingerprint) {
    registry.refuse(
        fmt::format("module {} was built for Chimera {} (module ABI {:016x}), but this is Chimera {} "
                    "(module ABI {:016x}): rebuild the library against this version",
                    name, stamp->version != nullptr ? stamp->version : "?", stamp->fingerprint,
                    chimera::kChimeraVersion, chimera::kModuleAbiFingerprint));
    return;
  }
  add();
}

namespace chimera {

Registry& Registry::global() {
  static Registry registry;  // built on first use, so registrations in any order find it
  return registry;
}

Result<void> Registry::add(ModuleInfo info) {
  std::string problem;
  if (info.name.empty() || !info.declare || !info.make) {
    problem = "a module needs a name, a declare function and a factory";
  } else if (find(info.name) != nullptr) {
    const std::string_view first = origin(info.name);
    problem = fmt::format("module '{}' is registered twice (the first comes from {})", info.name,
                          first.empty() ? std::string_view("the program itself") : first);
  }
  if (!problem.empty()) {
    refuse(problem);
    return make_error(Errc::kInvalidInput, std::move(problem));
  }
  if (capturing_) capture_.added.push_back(info.name);
  modules_.push_back(Entry{std::make_unique<ModuleInfo>(std::move(info)), capturing_ ? origin_ : std::string()});
  return {};
}

const ModuleInfo* Registry::find(std::string_view name) const {
  for (const auto& m : modules_)
    if (m.info->name == name) return m.info.get();
  return nullptr;
}

std::string_view Registry::origin(std::string_view name) const {
  for (const auto& m : modules_)
    if (m.info->name == name) return m.origin;
  return {};
}

void Registry::begin_capture(std::string origin) {
  capturing_ = true;
  origin_ = std::move(origin);
  capture_ = Capture{};
}

Registry::Capture Registry::end_capture() {
  capturing_ = false;
  origin_.clear();
  return std::exchange(capture_, Capture{});
}

void Registry::refuse(std::string message) {
  if (capturing_) capture_.refused.push_back(std::move(message));
}

void Registry::remove(std::string_view name) {
  std::erase_if(modules_, [&](const Entry& m) { return m.info->name == name; });
}

std::vector<const ModuleInfo*> Registry::list() const {
  std::vector<const ModuleInfo*> out;
  out.reserve(modules_.size());
  for (const auto& m : modules_) out.push_back(m.info.get());
  std::sort(out.begin(), out.end(), [](const ModuleInfo* a, const ModuleInfo* b) { return a->name < b->name; });
  return out;
}

}  // namespace chimera
