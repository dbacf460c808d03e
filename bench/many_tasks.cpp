// Framework CPU with N trivial tasks at 100 Hz on 2 cores (1,000 by default), on the real clock
// with real-time priorities, as `chimera run` would run them. The tasks' cycles are empty
// (bench_idle), so every nanosecond of CPU the process uses is the framework's: releases,
// wake-ups, transfers, statistics. A CPU figure counts only if the work it names was done: the
// cycles run against the cycles due in the measured window, the deadlines missed (from start),
// the tasks still ON, the release latency over every release of the window, and the memory.
//
//   many_tasks [--quick] [--out FILE] [--tasks N] [--seconds S]
//
// Keys (for 1,000 tasks): tasks_1000_at_100hz_cpu_percent (percent of the 2 cores' capacity),
// tasks_1000_cycles_run_percent, tasks_1000_missed_deadlines, tasks_1000_latency_p99_ns.

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "common/bench_util.hpp"
#include "common/real_subsystem.hpp"

namespace chimera::bench {
namespace {

struct Usage {
  std::int64_t wall_ns = 0;
  double cpu_s = 0;  // user + system, every thread of the process
  double user_s = 0;
  double sys_s = 0;
  long switches = 0;
};

Usage usage_now() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  Usage u;
  u.wall_ns = chimera::bench::monotonic_ns();
  u.user_s = static_cast<double>(ru.ru_utime.tv_sec) + static_cast<double>(ru.ru_utime.tv_usec) * 1e-6;
  u.sys_s = static_cast<double>(ru.ru_stime.tv_sec) + static_cast<double>(ru.ru_stime.tv_usec) * 1e-6;
  u.cpu_s = u.user_s + u.sys_s;
  u.switches = ru.ru_nvcsw + ru.ru_nivcsw;
  return u;
}

/// The process's resident memory, from /proc/self/status (kB); 0 if unknown.
long resident_kb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

/// Every task's figures at one moment: cycles, misses, and the release latencies, merged.
struct Totals {
  std::uint64_t cycles = 0;
  std::uint64_t missed = 0;
  std::size_t on = 0;
  std::map<std::int64_t, std::uint64_t> latency;  // bucket upper bound (ns) -> releases
};

Totals totals(const Subsystem& s) {
  Totals t;
  for (const auto& task : s.snapshot()) {
    t.cycles += task.stats.cycles;
    t.missed += task.stats.missed;
    t.on += task.state == TaskState::kOn ? 1 : 0;
    for (const auto& [upper, n] : task.stats.latency_histogram) t.latency[upper] += n;
  }
  return t;
}

/// The release latency below which `fraction` of the window's releases fall (bucket bounds).
std::int64_t window_percentile(const Totals& before, const Totals& after, double fraction) {
  std::map<std::int64_t, std::uint64_t> window = after.latency;
  std::uint64_t total = 0;
  for (auto& [upper, n] : window) {
    const auto b = before.latency.find(upper);
    n -= b == before.latency.end() ? 0 : std::min(n, b->second);
    total += n;
  }
  if (total == 0) return 0;
  const auto rank = static_cast<std::uint64_t>(fraction * static_cast<double>(total - 1)) + 1;
  std::uint64_t seen = 0;
  for (const auto& [upper, n] : window) {
    seen += n;
    if (seen >= rank) return upper;
  }
  return window.rbegin()->first;
}

}  // namespace
}  // namespace chimera::bench

int main(int argc, char** argv) {
  using namespace chimera;
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  int tasks = 1000;
  int seconds = args.quick ? 4 : 20;
  for (std::size_t i = 0; i + 1 < args.rest.size(); ++i) {
    if (args.rest[i] == "--tasks") tasks = std::stoi(args.rest[i + 1]);
    if (args.rest[i] == "--seconds") seconds = std::stoi(args.rest[i + 1]);
  }
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  std::string yaml = fmt::format("subsystem: bench_many_{}\ncpus: [0, 1]\ntasks:\n", ::getpid());
  std::string names;
  for (int i = 0; i < tasks; ++i) {
    yaml += fmt::format("  - name: t{:04}\n    module: bench_idle\n    frequency: 100Hz\n", i);
    names += fmt::format("{}t{:04}", i == 0 ? "" : ", ", i);
  }
  yaml += "configurations:\n  all: [" + names + "]\n";
  Fragment out;
  const long rss_before_kb = resident_kb();
  auto sub = real_subsystem(yaml, "many_tasks.yaml");
  if (!sub) {
    std::fprintf(stderr, "many_tasks: %s\n", sub.error().message.c_str());
    return 1;
  }
  const std::int64_t t_start = chimera::bench::monotonic_ns();
  if (auto r = (*sub)->start(); !r) {
    std::fprintf(stderr, "many_tasks: %s\n", r.error().message.c_str());
    return 1;
  }
  const double start_s = static_cast<double>(chimera::bench::monotonic_ns() - t_start) * 1e-9;
  const long rss_running_kb = resident_kb();
  (*sub)->run_for(100'000'000);  // the first releases of the group start
  const std::uint64_t missed_at_start = totals(**sub).missed;
  (*sub)->run_for(900'000'000);  // settle: every thread has run a few cycles
  // A snapshot of every task takes a while (milliseconds for thousands): the cycles are counted
  // between the snapshots' midpoints, the CPU between the two usage reads, outside them.
  const std::int64_t s0 = chimera::bench::monotonic_ns();
  const Totals c0 = totals(**sub);
  const std::int64_t mid0 = (s0 + chimera::bench::monotonic_ns()) / 2;
  const Usage u0 = usage_now();
  (*sub)->run_for(static_cast<std::int64_t>(seconds) * 1'000'000'000);
  const Usage u1 = usage_now();
  const std::int64_t s1 = chimera::bench::monotonic_ns();
  const Totals c1 = totals(**sub);
  const std::int64_t mid1 = (s1 + chimera::bench::monotonic_ns()) / 2;
  (*sub)->stop();

  const double wall_s = static_cast<double>(u1.wall_ns - u0.wall_ns) * 1e-9;
  const double cpu_s = u1.cpu_s - u0.cpu_s;
  const double cycles = static_cast<double>(c1.cycles - c0.cycles);
  const double expected = tasks * 100.0 * static_cast<double>(mid1 - mid0) * 1e-9;
  const double run_percent = expected > 0 ? 100.0 * cycles / expected : 0.0;
  const std::int64_t p99 = window_percentile(c0, c1, 0.99);
  const double cpu_percent = 100.0 * cpu_s / (wall_s * static_cast<double>(cpus));
  auto& d = out.details();
  d["tasks"] = tasks;
  d["rate_hz"] = 100;
  d["cpus"] = cpus;
  d["measured_s"] = wall_s;
  d["start_s"] = start_s;
  d["cpu_s"] = cpu_s;
  d["user_s"] = u1.user_s - u0.user_s;
  d["sys_s"] = u1.sys_s - u0.sys_s;
  d["cpu_percent_of_two_cores"] = cpu_percent;
  d["context_switches_per_s"] = static_cast<double>(u1.switches - u0.switches) / wall_s;
  d["cycles_per_s"] = cycles / (static_cast<double>(mid1 - mid0) * 1e-9);
  d["cycles_expected_per_s"] = tasks * 100.0;
  d["cycles_run_percent"] = run_percent;
  d["cpu_ns_per_cycle"] = cycles > 0 ? cpu_s * 1e9 / cycles : 0.0;
  d["missed_deadlines_from_start"] = c1.missed;
  d["missed_deadlines_in_window"] = c1.missed - c0.missed;
  d["missed_deadlines_in_first_100ms"] = missed_at_start;
  d["tasks_on_at_end"] = c1.on;
  d["latency_p50_ns"] = window_percentile(c0, c1, 0.50);
  d["latency_p99_ns"] = p99;
  d["latency_p999_ns"] = window_percentile(c0, c1, 0.999);
  d["rss_kb_before"] = rss_before_kb;
  d["rss_kb_running"] = rss_running_kb;
  d["memory_per_task_kb"] = static_cast<double>(rss_running_kb - rss_before_kb) / tasks;
  if (tasks == 1000) {
    out.result("tasks_1000_at_100hz_cpu_percent", cpu_percent);
    out.result("tasks_1000_cycles_run_percent", run_percent);
    out.result("tasks_1000_missed_deadlines", static_cast<double>(c1.missed));
    out.result("tasks_1000_latency_p99_ns", static_cast<double>(p99));
  }
  return out.write(args);
}
