#pragma once
// Names met so far in a subsystem file, each with the line it was first met on. The loader's
// name checks (a task defined twice, a configuration naming an unknown task, a key written twice)
// look names up here in constant time, so a file of n names is checked in O(n), not O(n^2).
// Private to src/config.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

namespace chimera::config_detail {

class NameIndex {
 public:
  /// The line `name` was recorded with, or none.
  [[nodiscard]] std::optional<int> find(std::string_view name) const;
  [[nodiscard]] bool contains(std::string_view name) const { return find(name).has_value(); }
  /// Records `name` at `line` unless it is recorded already; returns the earlier line if it was.
  std::optional<int> insert(std::string_view name, int line);

 private:
  // Transparent hashing: lookups by string_view make no string.
  struct Hash {
    using is_transparent = void;
    std::size_t operator()(std::string_view s) const noexcept { return std::hash<std::string_view>{}(s); }
  };
  std::unordered_map<std::string, int, Hash, std::equal_to<>> lines_;
};

/// How many lookups (find or insert) every NameIndex of this thread has made. The loader and
/// verification make a bounded number per name of the file: the test that proves the checks
/// linear counts them rather than timing them.
std::uint64_t name_lookups_in_this_thread();

}  // namespace chimera::config_detail
