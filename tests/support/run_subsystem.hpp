#pragma once
// Starting a subsystem from a YAML text for a test, on a test's own shared memory: the helper
// the executive, scheduling and reconfiguration tests share. A failure to load, create or start
// fails the test and returns nullptr.

#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/probe_module.hpp"

namespace chimera::testing {

inline std::unique_ptr<Subsystem> start_subsystem(const std::string& yaml, const Registry& registry,
                                                  ClockKind clock = ClockKind::kVirtual) {
  auto spec = load_subsystem_text(yaml, "test.yaml", registry);
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  if (!spec.ok()) return nullptr;
  RunOptions o;
  o.clock = clock;
  o.shm_suffix = unique_suffix();
  o.realtime_priorities = false;  // real clock: ordinary threads, the behaviour must not depend on SCHED_FIFO
  auto s = Subsystem::create(*spec, registry, o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  if (!s.ok()) return nullptr;
  auto started = (*s)->start();
  EXPECT_TRUE(started.ok()) << (started.ok() ? "" : started.error().message);
  return started.ok() ? std::move(*s) : nullptr;
}

/// The figures of task `name`; fails the test if there is none.
inline TaskSnapshot task_of(Subsystem& s, const std::string& name) {
  for (const auto& t : s.snapshot())
    if (t.name == name) return t;
  ADD_FAILURE() << "no task " << name;
  return {};
}

}  // namespace chimera::testing
