#pragma once
// The message a bad subsystem file is refused with, for the loader's error tests.

#include <string>
#include <string_view>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "unit/config/fake_modules.hpp"

namespace chimera::test {

/// Loads `text` as "pid.yaml" against the test registry; the test fails if it loads or fails
/// with anything but Errc::kInvalidInput.
inline std::string error_of(std::string_view text) {
  auto r = load_subsystem_text(text, "pid.yaml", config_test_registry());
  EXPECT_FALSE(r.ok()) << "loaded:\n" << text;
  if (r.ok()) return {};
  EXPECT_EQ(r.error().code, Errc::kInvalidInput);
  return r.error().message;
}

}  // namespace chimera::test
