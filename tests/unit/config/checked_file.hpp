#pragma once
// A subsystem file loaded and resolved against the test registry, for the resolution and
// verification tests. The resolution points into the spec, so both live here and never move.

#include <algorithm>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "unit/config/fake_modules.hpp"

namespace chimera::test {

class CheckedFile {
 public:
  /// Loads `text` (a test fails if it does not load) and resolves it.
  explicit CheckedFile(std::string_view text) { init(load_subsystem_text(text, "test.yaml", config_test_registry())); }
  /// The same for a file.
  static CheckedFile from_file(const std::string& path) { return CheckedFile(FromFile{path}); }

  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;
  CheckedFile(CheckedFile&&) = delete;
  CheckedFile& operator=(CheckedFile&&) = delete;
  ~CheckedFile() = default;

  [[nodiscard]] const SubsystemSpec& spec() const { return spec_; }
  [[nodiscard]] const Resolution& resolution() const { return resolution_; }
  [[nodiscard]] const ResolvedSubsystem& resolved() const { return resolution_.subsystem; }
  [[nodiscard]] std::vector<Violation> verify(const std::optional<std::string>& only = {}) const {
    return verify_subsystem(resolution_, only);
  }

  /// The binding of `port` of task `task`; fails the test if there is none.
  [[nodiscard]] PortBinding binding(std::string_view task, std::string_view port) const {
    const ResolvedTask* t = resolved().find_task(task);
    EXPECT_NE(t, nullptr) << "no task " << task;
    if (t == nullptr) return {};
    for (const auto& b : t->bindings)
      if (b.port == port) return b;
    ADD_FAILURE() << "task " << task << " has no port " << port;
    return {};
  }

 private:
  struct FromFile {
    std::string path;
  };
  explicit CheckedFile(const FromFile& f) { init(load_subsystem_file(f.path, config_test_registry())); }

  void init(Result<SubsystemSpec>&& loaded) {
    EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error().message);
    if (loaded.ok()) spec_ = *std::move(loaded);
    resolution_ = resolve_subsystem(spec_, config_test_registry());
  }

  SubsystemSpec spec_;
  Resolution resolution_;
};

/// The messages of `violations`, for readable assertions.
inline std::vector<std::string> messages(const std::vector<Violation>& violations) {
  std::vector<std::string> out;
  out.reserve(violations.size());
  for (const auto& v : violations) out.push_back(v.message);
  return out;
}

}  // namespace chimera::test
