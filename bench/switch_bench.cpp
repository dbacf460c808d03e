// Dynamic reconfiguration on the real clock: 10,000 switches at 1 kHz between two producers of
// one variable, with a consumer that stays ON (the robot interface's place), at real-time
// priorities as `chimera run` runs them.
//
//   switch_bench [--quick] [--out FILE] [--samples-dir DIR] [--switches N]
//
// Keys: switch_lost_cycles (the staying task's releases that did not run, plus the releases that
// no producer, or two, ran: the staying task's cycles against the producers' together), and
// switch_commit_latency_ns_p50 / _p99 (from the request to the commit at a cycle boundary). The
// staying task's cycles that did not read the value of their own release are counted beside it,
// with a control run of as long without a switch: the machine's stalls cause those too.

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "common/bench_util.hpp"
#include "common/real_subsystem.hpp"

int main(int argc, char** argv) {
  using namespace chimera;
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  int switches = args.quick ? 1000 : 10'000;
  for (std::size_t i = 0; i + 1 < args.rest.size(); ++i)
    if (args.rest[i] == "--switches") switches = std::stoi(args.rest[i + 1]);

  // Soft tasks with late: run: a late cycle on a shared machine must neither send a task to
  // ERROR nor be skipped; lateness is not what this measures, lost cycles are.
  const std::string yaml = fmt::format(R"(subsystem: bench_switch_{}
tasks:
  - {{name: a, module: bench_stamper, frequency: 1kHz, criticality: soft, late: run}}
  - {{name: b, module: bench_stamper, frequency: 1kHz, criticality: soft, late: run}}
  - {{name: robot, module: bench_stamp_check, frequency: 1kHz, criticality: soft, late: run}}
configurations:
  with_a: [a, robot]
  with_b: [b, robot]
)",
                                       ::getpid());
  auto sub = real_subsystem(yaml, "switch_bench.yaml");
  if (!sub) {
    std::fprintf(stderr, "%s\n", sub.error().message.c_str());
    return 1;
  }
  Subsystem& s = **sub;
  if (auto r = s.start(); !r) {
    std::fprintf(stderr, "%s\n", r.error().message.c_str());
    return 1;
  }
  // Create b once, so that every measured switch is a commit between existing tasks.
  if (auto r = s.switch_to("with_b"); !r || !s.switch_to("with_a")) {
    std::fprintf(stderr, "warm-up switch failed\n");
    return 1;
  }
  s.run_for(50'000'000);
  auto stats_of = [&](const char* name) {
    for (const auto& t : s.snapshot())
      if (t.name == name) return t.stats;
    return TaskStatsSnapshot{};
  };
  auto robot_of = [&] { return stats_of("robot"); };
  auto produced = [&] { return stats_of("a").cycles + stats_of("b").cycles; };
  // The control: as long again without switching, half of it under each producer (they may run
  // on different CPUs from the staying task, which then waits for them across CPUs). What the
  // machine's stalls cost the staying task there is not the switches' doing.
  const std::int64_t idle_ns = static_cast<std::int64_t>(switches) * 1'000'000;
  TaskStatsSnapshot idle_before = robot_of();
  double idle_stale_before = s.get("stale")->at(0);
  std::uint64_t idle_timeouts = 0;
  std::uint64_t idle_missed = 0;
  double idle_stale = 0;
  for (const char* config : {"with_b", "with_a"}) {
    s.run_for(idle_ns / 2);
    const TaskStatsSnapshot now = robot_of();
    idle_timeouts += now.order_timeouts - idle_before.order_timeouts;
    idle_missed += now.missed - idle_before.missed;
    idle_stale += s.get("stale")->at(0) - idle_stale_before;
    (void)s.switch_to(config);  // not counted: the measured switches come below
    s.run_for(10'000'000);
    idle_before = robot_of();
    idle_stale_before = s.get("stale")->at(0);
  }

  const TaskStatsSnapshot before = robot_of();
  const std::uint64_t produced_before = produced();
  const double stale_before = s.get("stale")->at(0);
  const std::int64_t t0 = s.now_ns();
  std::vector<std::uint32_t> commit;
  commit.reserve(static_cast<std::size_t>(switches));
  int failed = 0;
  for (int i = 0; i < switches; ++i) {
    auto r = s.switch_to(i % 2 == 0 ? "with_b" : "with_a");
    if (!r) {
      ++failed;
      continue;
    }
    commit.push_back(static_cast<std::uint32_t>(r->committed_ns - r->requested_ns));
  }
  s.run_for(20'000'000);  // the last switch's producer runs a few cycles
  const std::int64_t t1 = s.now_ns();
  const TaskStatsSnapshot after = robot_of();
  const std::uint64_t produced_after = produced();
  const double stale = s.get("stale")->at(0) - stale_before;
  s.stop();

  // The robot released every 1 ms from t0 to t1: that many cycles, each with a fresh value.
  const double expected = static_cast<double>(t1 - t0) / 1e6;
  const double ran = static_cast<double>(after.cycles - before.cycles);
  const double missing = std::max(0.0, expected - ran - 1.0);  // one release of slack at either edge
  // Exactly one producer runs each release: a gap (or a doubled release) at a switch shows as a
  // difference between the staying task's cycles and the producers' together.
  const double producer_gap = std::abs(ran - static_cast<double>(produced_after - produced_before));
  Fragment out;
  out.result("switch_lost_cycles", missing + producer_gap);
  std::vector<std::uint32_t> sorted = commit;
  auto stats = summary(sorted);
  if (!commit.empty()) {
    out.result("switch_commit_latency_ns_p50", stats["p50"].get<double>());
    out.result("switch_commit_latency_ns_p99", stats["p99"].get<double>());
  }
  auto& d = out.details();
  d["switches"] = switches;
  d["switches_failed"] = failed;
  d["switching_s"] = static_cast<double>(t1 - t0) * 1e-9;
  d["robot_cycles"] = ran;
  d["robot_cycles_expected"] = expected;
  d["robot_releases_not_run"] = missing;
  d["robot_cycles_without_fresh_value"] = stale;
  d["producer_cycles"] = static_cast<double>(produced_after - produced_before);
  d["producer_gap"] = producer_gap;
  d["robot_missed_deadlines"] = after.missed - before.missed;
  d["robot_order_timeouts"] = after.order_timeouts - before.order_timeouts;
  d["idle_s"] = static_cast<double>(idle_ns) * 1e-9;
  d["idle_cycles_without_fresh_value"] = idle_stale;
  d["idle_order_timeouts"] = idle_timeouts;
  d["idle_missed_deadlines"] = idle_missed;
  d["commit_latency_ns"] = stats;
  out.samples(args, "switch_commit_latency", commit);
  return out.write(args);
}
