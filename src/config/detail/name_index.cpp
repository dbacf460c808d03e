#include "name_index.hpp"

namespace chimera::config_detail {
namespace {

// Per thread: loads on other threads (the network API's) must not disturb a test's count.
thread_local std::uint64_t lookups = 0;

}  // namespace

std::optional<int> NameIndex::find(std::string_view name) const {
  ++lookups;
  const auto it = lines_.find(name);
  if (it == lines_.end()) return std::nullopt;
  return it->second;
}

std::optional<int> NameIndex::insert(std::string_view name, int line) {
  ++lookups;
  const auto [it, inserted] = lines_.try_emplace(std::string(name), line);
  if (inserted) return std::nullopt;
  return it->second;
}

std::uint64_t name_lookups_in_this_thread() { return lookups; }

}  // namespace chimera::config_detail
