// Framework CPU with 1,000 trivial tasks at 100 Hz on 2 cores, on the real clock with real-time
// priorities, as `chimera run` would run them. The tasks' cycles are empty (bench_idle), so every
// nanosecond of CPU the process uses is the framework's: releases, wake-ups, transfers, statistics.
//
//   many_tasks [--quick] [--out FILE] [--tasks N] [--seconds S]
//
// Key: tasks_1000_at_100hz_cpu_percent (percent of the 2 cores' capacity).

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
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
  u.wall_ns = monotonic_ns();
  u.user_s = static_cast<double>(ru.ru_utime.tv_sec) + static_cast<double>(ru.ru_utime.tv_usec) * 1e-6;
  u.sys_s = static_cast<double>(ru.ru_stime.tv_sec) + static_cast<double>(ru.ru_stime.tv_usec) * 1e-6;
  u.cpu_s = u.user_s + u.sys_s;
  u.switches = ru.ru_nvcsw + ru.ru_nivcsw;
  return u;
}

std::uint64_t total_cycles(const Subsystem& s) {
  std::uint64_t n = 0;
  for (const auto& t : s.snapshot()) n += t.stats.cycles;
  return n;
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
  auto sub = real_subsystem(yaml, "many_tasks.yaml");
  if (!sub) {
    std::fprintf(stderr, "%s\n", sub.error().message.c_str());
    return 1;
  }
  const std::int64_t t_start = monotonic_ns();
  if (auto r = (*sub)->start(); !r) {
    std::fprintf(stderr, "%s\n", r.error().message.c_str());
    return 1;
  }
  const double start_s = static_cast<double>(monotonic_ns() - t_start) * 1e-9;
  (*sub)->run_for(1'000'000'000);  // settle: every thread has run a few cycles
  const Usage u0 = usage_now();
  const std::uint64_t c0 = total_cycles(**sub);
  (*sub)->run_for(static_cast<std::int64_t>(seconds) * 1'000'000'000);
  const Usage u1 = usage_now();
  const std::uint64_t c1 = total_cycles(**sub);
  const auto snap = (*sub)->snapshot();
  (*sub)->stop();

  const double wall_s = static_cast<double>(u1.wall_ns - u0.wall_ns) * 1e-9;
  const double cpu_s = u1.cpu_s - u0.cpu_s;
  const double cycles = static_cast<double>(c1 - c0);
  std::vector<std::int64_t> p99s;
  std::uint64_t missed = 0;
  for (const auto& t : snap) {
    p99s.push_back(t.stats.latency_p99_ns);
    missed += t.stats.missed;
  }
  auto& d = out.details();
  d["tasks"] = tasks;
  d["rate_hz"] = 100;
  d["cpus"] = cpus;
  d["measured_s"] = wall_s;
  d["start_s"] = start_s;
  d["cpu_s"] = cpu_s;
  d["user_s"] = u1.user_s - u0.user_s;
  d["sys_s"] = u1.sys_s - u0.sys_s;
  d["context_switches_per_s"] = static_cast<double>(u1.switches - u0.switches) / wall_s;
  d["cycles_per_s"] = cycles / wall_s;
  d["cycles_expected_per_s"] = tasks * 100.0;
  d["cpu_ns_per_cycle"] = cycles > 0 ? cpu_s * 1e9 / cycles : 0.0;
  d["missed_deadlines"] = missed;
  d["latency_p99_ns_over_tasks"] = summary(p99s);
  d["cpu_percent_of_one_core"] = 100.0 * cpu_s / wall_s;
  if (tasks == 1000)
    out.result("tasks_1000_at_100hz_cpu_percent", 100.0 * cpu_s / (wall_s * static_cast<double>(cpus)));
  return out.write(args);
}
