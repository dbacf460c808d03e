#pragma once
// A benchmark's own subsystem, from YAML text, on the real clock.

#include <memory>
#include <string>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::bench {

/// Loads `yaml` (called `file` in messages) against the global registry and creates it on the
/// real clock; otherwise the first problem.
inline Result<std::unique_ptr<Subsystem>> real_subsystem(const std::string& yaml, const std::string& file) {
  auto spec = load_subsystem_text(yaml, file, Registry::global());
  if (!spec) return spec.error();
  RunOptions options;
  options.clock = ClockKind::kReal;
  return Subsystem::create(*spec, Registry::global(), options);
}

}  // namespace chimera::bench
