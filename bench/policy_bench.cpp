// The policies on the real clock: one task set that rate monotonic cannot schedule and EDF and
// MUF can (t1: 20 ms every 50 ms, t2: 35 ms every 70 ms, U = 0.9, on one CPU), run under each, with
// real-time priorities; the deadlines each misses. cpu_load spins on its thread's CPU clock, so
// each cycle is its execution time of CPU however often it is preempted. The same set on the
// virtual clock is tests/unit/exec/scheduling_policy_test.cpp's, scaled.
//
//   policy_bench [--quick] [--out FILE]
//
// No key of the issue's table: the figures go to the report's details (policies).

#include <unistd.h>

#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "common/bench_util.hpp"
#include "common/real_subsystem.hpp"

int main(int argc, char** argv) {
  using namespace chimera;
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  const std::int64_t run_ns = args.quick ? 1'750'000'000 : 7'000'000'000;  // 5 or 20 hyperperiods of 350 ms
  Fragment out;
  auto& d = out.details();
  for (const char* scheduler : {"rm", "edf", "muf"}) {
    const std::string yaml = fmt::format(R"(subsystem: bench_policy_{}_{}
scheduler: {}
cpus: [0]
tasks:
  - {{name: t1, module: cpu_load, period: 50ms, criticality: soft, late: run, params: {{exec: 0.020}}}}
  - {{name: t2, module: cpu_load, period: 70ms, criticality: soft, late: run, params: {{exec: 0.035}}}}
)",
                                         scheduler, ::getpid(), scheduler);
    auto sub = real_subsystem(yaml, "policy_bench.yaml");
    if (!sub) {
      std::fprintf(stderr, "%s\n", sub.error().message.c_str());
      return 1;
    }
    if (!(*sub)->start()) {
      std::fprintf(stderr, "%s: cannot start\n", scheduler);
      return 1;
    }
    (*sub)->run_for(run_ns);
    const auto tasks = (*sub)->snapshot();
    (*sub)->stop();
    for (const auto& t : tasks) {
      d[scheduler][t.name]["cycles"] = t.stats.cycles;
      d[scheduler][t.name]["missed"] = t.stats.missed;
      d[scheduler][t.name]["response_max_ns"] = t.stats.response_max_ns;
    }
  }
  d["run_s"] = static_cast<double>(run_ns) * 1e-9;
  d["hyperperiods"] = static_cast<double>(run_ns) / 350e6;
  return out.write(args);
}
