#include "measure.hpp"

#include <unistd.h>

#include <algorithm>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "chimera/module/registry.hpp"

namespace chimera::cli {

namespace {

constexpr std::int64_t kMinMeasureNs = 1'000'000'000;
constexpr std::int64_t kPeriodsMeasured = 20;

Result<std::vector<TaskSnapshot>> measure_once(const SubsystemSpec& spec, const std::string& configuration,
                                               ClockKind clock, std::int64_t for_ns) {
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
  subsystem.run_for(for_ns);
  auto tasks = subsystem.snapshot();
  subsystem.stop();
  for (const auto& e : subsystem.drain_events()) spdlog::warn("while measuring, task {}: {}", e.task, e.text);
  return tasks;
}

}  // namespace

std::int64_t measurement_length_ns(const SubsystemSpec& spec, const std::string& configuration) {
  std::int64_t longest = 0;
  if (const ConfigurationSpec* c = spec.find_configuration(configuration))
    for (const auto& name : c->tasks)
      if (const TaskSpec* t = spec.find_task(name)) longest = std::max(longest, t->period_ns.value_or(0));
  return std::max(kMinMeasureNs, kPeriodsMeasured * longest);
}

Result<analysis::WcetProfile> measure_profile(const SubsystemSpec& spec, const std::string& configuration,
                                              ClockKind clock, std::int64_t for_ns, int runs, double margin) {
  std::vector<TaskSnapshot> least;  // per task: the run with the shortest longest cycle
  for (int run = 0; run < runs; ++run) {
    auto tasks = measure_once(spec, configuration, clock, for_ns);
    if (!tasks) return tasks.error();
    if (least.empty()) {
      least = *std::move(tasks);
      continue;
    }
    for (std::size_t i = 0; i < least.size() && i < tasks->size(); ++i)
      if ((*tasks)[i].stats.cycles > 0 &&
          (least[i].stats.cycles == 0 || (*tasks)[i].stats.exec_max_ns < least[i].stats.exec_max_ns))
        least[i] = (*tasks)[i];
  }

  analysis::WcetProfile profile;
  profile.subsystem = spec.name;
  profile.clock = clock == ClockKind::kVirtual ? "virtual" : "real";
  for (const auto& t : least)
    if (t.stats.cycles > 0)
      profile.tasks.push_back(
          analysis::measured_entry(t.name, t.stats.exec_max_ns, t.stats.cycles, margin, t.stats.exec_p99_ns));
  return profile;
}

}  // namespace chimera::cli
