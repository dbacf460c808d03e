// Opening another subsystem file in a running subsystem (`open FILE`, POST /api/open): what
// Node-RED's deploy and RTSystemEditor's "open system" do. The runtime is made anew from the file,
// as the live assembly's add makes it anew for one more task, after every task was turned off and
// killed; the file's start configuration is then turned on, as `chimera run FILE` would.

#include <mutex>
#include <shared_mutex>

#include <fmt/format.h>

#include "chimera/config/verify.hpp"
#include "subsystem_impl.hpp"

namespace chimera {

Result<void> Subsystem::replace(SubsystemSpec next) {
  Impl& m = *impl_;
  // Phase 1: everything about the file checked while the present subsystem runs on.
  {
    std::lock_guard<std::mutex> lock(m.ops_mutex);
    if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
    // Exports and imports are the run's bridge's (apps/chimera/dds_bridge.hpp), which follows
    // the table made anew for the file to the file's exports and imports.
  }
  if (auto cpus = check_task_cpus(next); !cpus) return make_error(Errc::kInvalidInput, "open: " + cpus.error().message);
  {
    const Resolution resolution = resolve_subsystem(next, *m.registry);
    const auto violations = verify_subsystem(resolution, next.start);
    if (!violations.empty())
      return make_error(Errc::kIllegal, fmt::format("open: {}: configuration '{}' is not legal: {}", next.file,
                                                    next.start, violations.front().message));
  }

  // Phase 2: every task off, then killed (as stop does), and the runtime made anew for the file.
  m.executive->stop_serving();  // the service thread takes ops_mutex to serve a request
  Result<void> outcome;
  bool serve_again = false;
  bool put_back = false;  // the runtime was made again for the subsystem as it was
  {
    std::lock_guard<std::mutex> lock(m.ops_mutex);
    serve_again = m.serving && !m.stopped;
    if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
    m.off_then_kill_every_task();
    m.events->collect(*m.tasks);
    for (std::size_t i = 0; i < m.tasks->size(); ++i) {
      const Task& task = (*m.tasks)[i];
      if (task.state() != TaskState::kNotCreated)
        outcome = make_error(Errc::kState, fmt::format("open: task {} could not be killed (it is {}); the subsystem "
                                                       "stays, its other tasks killed",
                                                       task.name(), state_name(task.state())));
    }
    if (outcome) {
      const SubsystemSpec current = m.live_spec();
      const std::string was_on = m.reconfiguration->configuration();
      const std::string first = next.start;
      outcome = m.rebuild_runtime(std::move(next), first, current, was_on);
      put_back = !outcome;  // started anew below
    }
  }
  if (!outcome) {
    std::string why =
        outcome.error().message.starts_with("open: ") ? outcome.error().message : "open: " + outcome.error().message;
    if (put_back) {
      // Its configuration on again, as the operator had it; its tasks' state begins anew.
      const auto again = start();
      why += again ? fmt::format("; the subsystem before runs again, configuration '{}' started anew", configuration())
                   : fmt::format("; the subsystem before is back, but its configuration did not start: {}",
                                 again.error().message);
      if (!again) serve_requests();
    } else if (serve_again) {
      serve_requests();
    }
    return make_error(outcome.error().code, why);
  }
  // The file's start configuration on, as chimera run FILE starts it; start() serves again.
  if (auto started = start(); !started) {
    serve_requests();  // start() serves only once its configuration is on
    return make_error(started.error().code, fmt::format("open: {} is open, but its configuration '{}' did not "
                                                        "start: {}",
                                                        impl_->spec.file, impl_->spec.start, started.error().message));
  }
  return {};
}

}  // namespace chimera
