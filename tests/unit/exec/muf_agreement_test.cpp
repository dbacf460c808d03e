// MUF's analysis and runtime agree (issue 12, item 5): on task sets generated from a fixed seed
// (1 or 2 CPUs, hard and soft, utilisation 0.8 to 1.2 per CPU, harmonic and non-harmonic
// periods, execution time given by `virtual_exec:` or by cpu_load's `exec`), the critical set the
// executive orders jobs by is, task by task and CPU by CPU, the one analysis names, and every
// task analysis calls "meets (critical)" misses no deadline in two hyperperiods on the virtual
// clock. Analysis takes each task's C from the run's own statistics, which on the virtual clock
// are the simulated time (what `chimera analyze` measures).

#include <algorithm>
#include <cstdint>
#include <iostream>
#include <numeric>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "chimera/analysis/cpu_assignment.hpp"
#include "chimera/analysis/release_order.hpp"
#include "chimera/analysis/schedulability.hpp"
#include "chimera/analysis/task_models.hpp"
#include "chimera/analysis/wcet_profile.hpp"
#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "chimera/control/subsystem.hpp"
#include "exec/schedule_plan.hpp"
#include "support/run_subsystem.hpp"
#include "support/trace_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kUs = 1'000;
constexpr std::int64_t kMs = 1'000'000;

// splitmix64: the same numbers on every standard library (std's distributions are not).
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  int below(int n) { return static_cast<int>(next() % static_cast<std::uint64_t>(n)); }
  double unit() { return static_cast<double>(next() >> 11) / static_cast<double>(1ULL << 53); }

 private:
  std::uint64_t state_;
};

// How a generated task gets its execution time C on the virtual clock.
enum class ExecFrom { kVirtualExec, kCpuLoad, kCpuLoadWithWcet };

struct GeneratedTask {
  std::string name;
  std::int64_t c_ns = 0;
  std::int64_t t_ns = 0;
  std::int64_t d_ns = 0;  // 0: the period
  bool hard = true;
  int cpu = -1;  // -1: assigned
  int priority = 0;
  ExecFrom exec = ExecFrom::kVirtualExec;
};

struct GeneratedSet {
  int cpus = 1;
  std::vector<GeneratedTask> tasks;
  std::int64_t hyperperiod_ns = 1;
};

std::string yaml_of(const GeneratedSet& set) {
  std::string out =
      fmt::format("subsystem: muf_gen\nscheduler: muf\ncpus: [{}]\ntasks:\n", set.cpus == 1 ? "0" : "0, 1");
  for (const auto& t : set.tasks) {
    out += fmt::format("  - {{name: {}, module: cpu_load, period: {}us, criticality: {}", t.name, t.t_ns / kUs,
                       t.hard ? "hard" : "soft");
    if (t.d_ns > 0) out += fmt::format(", deadline: {}us", t.d_ns / kUs);
    if (t.cpu >= 0) out += fmt::format(", cpu: {}", t.cpu);
    if (t.priority != 0) out += fmt::format(", priority: {}", t.priority);
    if (t.exec == ExecFrom::kVirtualExec) {
      out += fmt::format(", virtual_exec: {}us, params: {{recover: true}}}}\n", t.c_ns / kUs);
    } else {
      if (t.exec == ExecFrom::kCpuLoadWithWcet) out += fmt::format(", wcet: {}us", t.c_ns / kUs);
      out += fmt::format(", params: {{exec: {:.6f}, recover: true}}}}\n", static_cast<double>(t.c_ns) / 1e9);
    }
  }
  return out;
}

GeneratedSet generate(Random& random, int index) {
  static const std::vector<std::int64_t> kHarmonic{5 * kMs, 10 * kMs, 20 * kMs, 40 * kMs};
  static const std::vector<std::int64_t> kNonHarmonic{4 * kMs, 6 * kMs, 7 * kMs, 10 * kMs, 15 * kMs};
  GeneratedSet set;
  set.cpus = index % 2 == 0 ? 1 : 2;
  const auto& periods = (index / 2) % 2 == 0 ? kHarmonic : kNonHarmonic;
  for (int cpu = 0; cpu < set.cpus; ++cpu) {
    const int n = 2 + random.below(4);               // 2 to 5 tasks on this CPU
    const double total = 0.8 + 0.4 * random.unit();  // U from 0.8 to 1.2
    std::vector<double> weights;
    weights.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) weights.push_back(0.2 + random.unit());
    const double sum = std::accumulate(weights.begin(), weights.end(), 0.0);
    for (int i = 0; i < n; ++i) {
      GeneratedTask t;
      t.name = fmt::format("t{}", set.tasks.size());
      t.t_ns = periods[static_cast<std::size_t>(random.below(static_cast<int>(periods.size())))];
      // C to 10 µs, at least 100 µs and at most the period.
      const auto c = static_cast<std::int64_t>(total * weights[static_cast<std::size_t>(i)] / sum *
                                               static_cast<double>(t.t_ns) / (10.0 * kUs));
      t.c_ns = std::clamp<std::int64_t>(c * 10 * kUs, 100 * kUs, t.t_ns);
      if (random.below(4) == 0) {  // a constrained deadline: the processor-demand test
        const std::int64_t d = t.t_ns * (6 + random.below(4)) / 10 / kUs * kUs;
        t.d_ns = std::max(d, t.c_ns);
      }
      t.hard = random.below(4) < 3;
      // On two CPUs most tasks are pinned (the loads above are per CPU), a few assigned.
      t.cpu = set.cpus == 1 || random.below(4) != 0 ? cpu : -1;
      t.priority = random.below(3) == 0 ? random.below(3) : 0;
      // Half by virtual_exec, a third by cpu_load with a wcet (both known to the run), a sixth by
      // cpu_load alone (known only to the run's statistics).
      const int how = random.below(6);
      t.exec = how < 3 ? ExecFrom::kVirtualExec : how < 5 ? ExecFrom::kCpuLoadWithWcet : ExecFrom::kCpuLoad;
      set.tasks.push_back(std::move(t));
    }
  }
  set.hyperperiod_ns = 1;
  for (const auto& t : set.tasks) set.hyperperiod_ns = std::lcm(set.hyperperiod_ns, t.t_ns);
  return set;
}

struct Outcome {
  int hard_left_out = 0;               // hard tasks outside the critical set
  int soft_critical = 0;               // soft tasks admitted
  int meets_critical = 0;              // tasks analysis guarantees
  int meets_beside_unfit = 0;          // ... on a CPU where a hard task does not fit
  int misses_outside = 0;              // tasks outside the guarantee that did miss
  int simulated_c_unknown_to_run = 0;  // critical tasks whose C only the run's statistics give
};

// Runs `yaml` for `for_ns` on the virtual clock, analyses it with the C the run measured in
// simulated time, and checks that the runtime's critical set is analysis' and that every task
// analysis guarantees met every deadline.
void check_agreement(const std::string& yaml, std::int64_t for_ns, Outcome& outcome) {
  SCOPED_TRACE(yaml);
  const Registry& registry = testing::scheduling_registry();
  auto spec = load_subsystem_text(yaml, "test.yaml", registry);
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  const ConfigurationSpec* config = spec->find_configuration(spec->start);
  ASSERT_NE(config, nullptr);

  // The runtime's plan: what both executives order jobs by (and the CPU each task runs on).
  const Resolution resolution = resolve_subsystem(*spec, registry);
  const std::vector<int> cpus = subsystem_cpus(*spec);
  const analysis::ReleaseOrder order = analysis::compute_release_order(resolution.subsystem);
  const SchedulePlan plan = make_schedule_plan(resolution.subsystem, order, cpus, config->tasks);

  auto run = testing::start_subsystem(yaml, registry);
  ASSERT_TRUE(run);
  run->run_for(for_ns);
  const auto snapshot = run->snapshot();

  // Analysis, with each task's C as `chimera analyze` measures it: its simulated time.
  analysis::WcetProfile measured;
  for (const auto& t : snapshot) {
    if (t.stats.cycles == 0) continue;  // starved outside the critical set: its C stays unknown, as in analyze
    ASSERT_TRUE(t.stats.exec_simulated) << t.name;
    auto entry = analysis::measured_entry(t.name, t.stats.exec_max_ns, t.stats.cycles, 1.0);
    entry.simulated = true;
    measured.tasks.push_back(std::move(entry));
  }
  const auto models = analysis::task_models(*spec, config->tasks, nullptr, &measured, &order);
  const auto file_cpu = analysis::assign_subsystem_cpus(*spec, order, cpus);
  std::vector<int> cpu_of;
  cpu_of.reserve(models.size());
  for (const auto& m : models) cpu_of.push_back(file_cpu[static_cast<std::size_t>(m.file_index)]);
  const auto result = analysis::analyse_configuration(models, cpu_of, cpus, SchedulerKind::kMuf);

  for (const auto& cpu : result.cpus) {
    bool unfit_here = false;
    for (const auto& r : cpu.tasks) unfit_here = unfit_here || (models[r.index].hard && !r.critical);
    for (const auto& r : cpu.tasks) {
      const analysis::TaskModel& m = models[r.index];
      const auto i = static_cast<std::size_t>(m.file_index);
      const TaskSnapshot& ran = snapshot[i];
      EXPECT_EQ(plan.cpu[i], cpu.cpu) << m.name << ": the run and analysis place it alike";
      EXPECT_EQ(plan.urgency[i].critical, r.critical)
          << m.name << " on cpu " << cpu.cpu << ": the run's critical set is analysis'";
      if (r.critical && r.verdict == analysis::Verdict::kMeets) {
        EXPECT_EQ(ran.stats.missed, 0u) << m.name << " is guaranteed (meets, critical) and missed";
        EXPECT_EQ(ran.state, TaskState::kOn) << m.name;
        ++outcome.meets_critical;
        if (unfit_here) ++outcome.meets_beside_unfit;
      } else if (ran.stats.missed > 0) {
        ++outcome.misses_outside;
      }
      if (m.hard && !r.critical) ++outcome.hard_left_out;
      if (!m.hard && r.critical) ++outcome.soft_critical;
      if (r.critical && run_known_wcet(m) == 0) ++outcome.simulated_c_unknown_to_run;
    }
  }
}

TEST(MufAgreement, AHardTaskThatDoesNotFitTakesNoTimeFromTheCriticalSet) {
  // The case: y (3 of 5 ms) and z (2 of 10 ms) fit (0.8); x (3 of 6 ms) does not. Were x
  // critical it would share EDF with y and z at 1.3 and make them miss: it is left out, and they
  // meet every deadline while x misses.
  const std::string yaml =
      "subsystem: muf_unfit\nscheduler: muf\ncpus: [0]\ntasks:\n"
      "  - {name: x, module: cpu_load, period: 6ms, virtual_exec: 3ms, params: {recover: true}}\n"
      "  - {name: y, module: cpu_load, period: 5ms, virtual_exec: 3ms, params: {recover: true}}\n"
      "  - {name: z, module: cpu_load, period: 10ms, virtual_exec: 2ms, params: {recover: true}}\n"
      "  - {name: s, module: cpu_load, period: 30ms, criticality: soft, virtual_exec: 1ms}\n";
  Outcome outcome;
  check_agreement(yaml, 60 * kMs, outcome);
  EXPECT_EQ(outcome.hard_left_out, 1);
  EXPECT_EQ(outcome.meets_critical, 2);  // y and z
  EXPECT_EQ(outcome.meets_beside_unfit, 2);
  EXPECT_EQ(outcome.soft_critical, 0);   // s would fit beside y and z, but a hard task does not
  EXPECT_GE(outcome.misses_outside, 1);  // x
}

TEST(MufAgreement, GeneratedSetsOnTheVirtualClock) {
  Random random(20261202);
  Outcome outcome;
  constexpr int kSets = 96;
  for (int i = 0; i < kSets; ++i) {
    const GeneratedSet set = generate(random, i);
    check_agreement(yaml_of(set), 2 * set.hyperperiod_ns, outcome);
    if (::testing::Test::HasFatalFailure()) return;
  }
  // The sets exercise every rule: hard tasks left out beside guaranteed ones, soft tasks admitted,
  // critical tasks whose C the run does not know, and misses outside the guarantee.
  EXPECT_GE(outcome.hard_left_out, 10);
  EXPECT_GE(outcome.meets_beside_unfit, 10);
  EXPECT_GE(outcome.soft_critical, 20);
  EXPECT_GE(outcome.meets_critical, 200);
  EXPECT_GE(outcome.simulated_c_unknown_to_run, 20);
  EXPECT_GE(outcome.misses_outside, 50);
  std::cout << fmt::format(
      "{} sets: {} tasks guaranteed ({} beside an unfit hard task), {} hard left out, {} soft admitted, {} critical "
      "of C unknown to the run, {} unguaranteed tasks missed\n",
      kSets, outcome.meets_critical, outcome.meets_beside_unfit, outcome.hard_left_out, outcome.soft_critical,
      outcome.simulated_c_unknown_to_run, outcome.misses_outside);
}

}  // namespace
}  // namespace chimera
