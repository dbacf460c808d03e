#include "measure.hpp"

#include <unistd.h>

#include <algorithm>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "chimera/core/duration_text.hpp"
#include "chimera/exec/clock.hpp"
#include "chimera/module/registry.hpp"
#include "stop_request.hpp"

namespace chimera::cli {

namespace {

constexpr std::int64_t kMinMeasureNs = 1'000'000'000;
constexpr std::int64_t kPeriodsMeasured = 20;
// Releases of one measuring run, every task together: at a few microseconds each on the virtual
// clock, seconds of host time. A file of many fast tasks is measured for a shorter time.
constexpr double kMostReleases = 2'000'000;
// The measuring runs are made in slices, so that a signal or the host-time limit ends them
// between two slices (and the regions go with the subsystem's stop()).
constexpr std::int64_t kSliceNs = 10'000'000;

Result<std::vector<TaskSnapshot>> measure_once(const SubsystemSpec& spec, const std::string& configuration,
                                               ClockKind clock, std::int64_t for_ns, std::int64_t host_deadline_ns) {
  static int runs = 0;  // one process may measure several times, one run after the other
  RunOptions options;
  options.clock = clock;
  options.configuration = configuration;
  options.shm_suffix = fmt::format("_measure_{}_{}", ::getpid(), runs++);
  options.realtime_priorities = clock == ClockKind::kReal;
  options.measure_cpu_time = true;  // a task's C is its own CPU time, not the wall clock's
  auto created = Subsystem::create(spec, Registry::global(), options);
  if (!created) return created.error();
  Subsystem& subsystem = **created;
  if (auto started = subsystem.start(); !started) {
    subsystem.stop();
    return started.error();
  }
  for (std::int64_t done = 0; done < for_ns;) {
    const std::int64_t slice = std::min(kSliceNs, for_ns - done);
    subsystem.run_for(slice);
    done += slice;
    if (done < for_ns && (stop_requested() || monotonic_ns() > host_deadline_ns)) {
      subsystem.stop();
      if (stop_requested()) return make_error(Errc::kState, "stopped by a signal while measuring");
      return make_error(Errc::kInvalidInput,
                        fmt::format("the measuring run took more than {} s of host time ({} of {} simulated); give "
                                    "the tasks wcet: or a profile with --wcet-from",
                                    kMeasureHostLimitNs / 1'000'000'000, format_duration(done), format_duration(for_ns)));
    }
  }
  auto tasks = subsystem.snapshot();
  subsystem.stop();
  for (const auto& e : subsystem.drain_events()) spdlog::warn("while measuring, task {}: {}", e.task, e.text);
  return tasks;
}

// The execution time a task's budget is made from: on the virtual clock its simulated time when
// it has some (what the virtual clock charges it), else, and on the real clock, the host's.
bool simulated_time(const TaskStatsSnapshot& s) { return s.exec_simulated && s.exec_max_ns > 0; }
std::int64_t longest_cycle_ns(const TaskStatsSnapshot& s) {
  return simulated_time(s) ? s.exec_max_ns : s.host_exec_max_ns;
}

}  // namespace

std::int64_t measurement_length_ns(const SubsystemSpec& spec, const std::string& configuration) {
  std::int64_t longest = 0;
  double releases_per_ns = 0;
  if (const ConfigurationSpec* c = spec.find_configuration(configuration))
    for (const auto& name : c->tasks)
      if (const TaskSpec* t = spec.find_task(name); t != nullptr && t->period_ns.value_or(0) > 0) {
        longest = std::max(longest, *t->period_ns);
        releases_per_ns += 1.0 / static_cast<double>(*t->period_ns);
      }
  const std::int64_t wanted = std::max(kMinMeasureNs, kPeriodsMeasured * longest);
  if (releases_per_ns * static_cast<double>(wanted) <= kMostReleases) return wanted;
  // Too many releases: as many as the bound allows, but one period of the slowest task at least.
  return std::max(longest, static_cast<std::int64_t>(kMostReleases / releases_per_ns));
}

Result<analysis::WcetProfile> measure_profile(const SubsystemSpec& spec, const std::string& configuration,
                                              ClockKind clock, std::int64_t for_ns, int runs, double margin,
                                              double simulated_margin) {
  std::vector<TaskSnapshot> least;  // per task: the run with the shortest longest cycle
  const std::int64_t host_deadline_ns = monotonic_ns() + kMeasureHostLimitNs;
  for (int run = 0; run < runs; ++run) {
    auto tasks = measure_once(spec, configuration, clock, for_ns, host_deadline_ns);
    if (!tasks) return tasks.error();
    if (least.empty()) {
      least = *std::move(tasks);
      continue;
    }
    for (std::size_t i = 0; i < least.size() && i < tasks->size(); ++i)
      if ((*tasks)[i].stats.cycles > 0 &&
          (least[i].stats.cycles == 0 || longest_cycle_ns((*tasks)[i].stats) < longest_cycle_ns(least[i].stats)))
        least[i] = (*tasks)[i];
  }

  analysis::WcetProfile profile;
  profile.subsystem = spec.name;
  profile.clock = clock == ClockKind::kVirtual ? "virtual" : "real";
  for (const auto& t : least) {
    if (t.stats.cycles == 0) continue;
    const bool simulated = simulated_time(t.stats);
    // The host's p99 is not kept on the virtual clock (only its mean and max).
    const std::optional<std::int64_t> p99 =
        simulated || !t.stats.exec_simulated ? std::optional(t.stats.exec_p99_ns) : std::nullopt;
    auto entry = analysis::measured_entry(t.name, longest_cycle_ns(t.stats), t.stats.cycles,
                                          simulated ? simulated_margin : margin, p99);
    entry.simulated = simulated;
    profile.tasks.push_back(std::move(entry));
  }
  return profile;
}

}  // namespace chimera::cli
