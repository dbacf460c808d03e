#pragma once
// A test's subsystem file with module processes, made and started as `chimera run` would: the
// file's plugins loaded, the built chimera command as the workers, without real-time priorities
// (the tests run anywhere; priorities are not their subject), its region named after the test
// process. Shared by the tests of this folder.

#include <unistd.h>

#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/plugins.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::test {

/// The subsystem of file `path`, started; nullptr, with the reason as a test failure, if it cannot
/// be. `options` carries what the test sets beyond the above.
inline std::unique_ptr<Subsystem> started_subsystem(const std::string& path, RunOptions options = {}) {
  auto plugins = load_file_plugins(path);
  if (!plugins) {
    ADD_FAILURE() << plugins.error().message;
    return nullptr;
  }
  auto spec = load_subsystem_file(path, Registry::global());
  if (!spec) {
    ADD_FAILURE() << spec.error().message;
    return nullptr;
  }
  options.realtime_priorities = false;
  options.shm_suffix = "_" + std::to_string(::getpid());
  options.worker_program = CHIMERA_BIN;
  auto made = Subsystem::create(*spec, Registry::global(), options);
  if (!made) {
    ADD_FAILURE() << made.error().message;
    return nullptr;
  }
  if (auto started = (*made)->start(); !started) {
    ADD_FAILURE() << started.error().message;
    return nullptr;
  }
  return std::move(*made);
}

}  // namespace chimera::test
