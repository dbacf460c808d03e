// A same-rate chain split over two CPUs (issue 12): at every release the consumer waits for its
// producer on the other CPU (the same-rate rule), and analysis counts that wait as the consumer's
// release jitter. The virtual clock's response times against analysis's, to the nanosecond; and
// placement, left to itself, keeps the chain on one CPU so that nobody waits.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/analysis/cpu_assignment.hpp"
#include "chimera/analysis/release_order.hpp"
#include "chimera/analysis/schedulability.hpp"
#include "chimera/analysis/task_models.hpp"
#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "support/run_subsystem.hpp"
#include "support/trace_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kUs = 1'000;

// p (counter) feeds c (follower) through `count`, both every 10 ms; each CPU has a 5 ms task that
// rm ranks above them. On CPU 0 hog0 runs 0-3 ms and p 3-4.5 ms: R(p) = 4.5 ms. On CPU 1, h1 runs
// 0-1 ms, c waits for p until 4.5 ms, runs 0.5 ms, is preempted by h1's next job at 5 ms and ends
// at 7.5 ms: R(c) = 4.5 ms of waiting + 3 ms. Without the wait analysis would say 3 ms.
std::string split_chain(const std::string& c_extra, bool pinned) {
  const auto cpu = [&](int n) { return pinned ? ", cpu: " + std::to_string(n) : std::string(); };
  return "subsystem: s\nscheduler: rm\ncpus: [0, 1]\ntasks:\n"
         "  - {name: p, module: counter, period: 10ms, virtual_exec: 1500us" +
         cpu(0) +
         "}\n"
         "  - {name: hog0, module: tracer, period: 5ms, virtual_exec: 3ms" +
         cpu(0) +
         "}\n"
         "  - {name: c, module: follower, period: 10ms, virtual_exec: 2ms" +
         cpu(1) + c_extra +
         "}\n"
         "  - {name: h1, module: tracer, period: 5ms, virtual_exec: 1ms" +
         cpu(1) + "}\n";
}

struct Analysed {
  std::vector<analysis::TaskModel> models;
  analysis::ConfigurationResult result;

  [[nodiscard]] const analysis::TaskResult& of(const std::string& name) const {
    for (const auto& cpu : result.cpus)
      for (const auto& r : cpu.tasks)
        if (models[r.index].name == name) return r;
    ADD_FAILURE() << "no result for " << name;
    return result.cpus.front().tasks.front();
  }
};

// What `chimera analyze` does, without the measuring: the same functions, the same order.
Analysed analyse(const std::string& yaml) {
  auto spec = load_subsystem_text(yaml, "chain.yaml", testing::scheduling_registry());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  const Resolution resolution = resolve_subsystem(*spec, testing::scheduling_registry());
  const analysis::ReleaseOrder order = analysis::compute_release_order(resolution.subsystem);
  const std::vector<int> cpus{0, 1};
  const auto file_cpu = analysis::assign_subsystem_cpus(*spec, order, cpus);
  Analysed a;
  a.models = analysis::task_models(*spec, spec->configurations.front().tasks, nullptr, nullptr, &order);
  std::vector<int> cpu_of;
  for (const auto& m : a.models) cpu_of.push_back(file_cpu[static_cast<std::size_t>(m.file_index)]);
  a.result = analysis::analyse_configuration(a.models, cpu_of, cpus, spec->scheduler,
                                             analysis::AnalysisOptions{.overhead_ns = 0});
  return a;
}

TEST(CrossCpuChain, TheConsumersWaitIsItsJitterAndTheVirtualClockAgreesExactly) {
  const std::string yaml = split_chain("", true);
  const Analysed a = analyse(yaml);
  EXPECT_TRUE(a.result.feasible);
  EXPECT_EQ(a.of("p").response_ns, 4500 * kUs);
  EXPECT_EQ(a.of("c").release_jitter_ns, 4500 * kUs);
  EXPECT_EQ(a.of("c").response_ns, 7500 * kUs);
  EXPECT_EQ(a.of("c").reason, "after waiting up to 4.5 ms for p on another CPU");
  EXPECT_EQ(a.of("h1").release_jitter_ns, 0);

  auto s = testing::start_subsystem(yaml, testing::scheduling_registry());
  ASSERT_TRUE(s);
  s->run_for(200 * kMs);
  const auto p = testing::task_of(*s, "p").stats;
  const auto c = testing::task_of(*s, "c").stats;
  EXPECT_EQ(p.cycles, 20u);
  EXPECT_EQ(c.cycles, 20u);
  EXPECT_EQ(p.response_max_ns, a.of("p").response_ns);
  EXPECT_EQ(c.response_max_ns, a.of("c").response_ns) << "analysis's bound is the worst case, met exactly";
  EXPECT_EQ(c.missed, 0u);
  EXPECT_EQ(c.order_timeouts, 0u);
  EXPECT_EQ(s->get("copy")->at(0), 20.0) << "c read p's value of the same release";
}

// With a 7 ms deadline the wait (4.5 ms) is past half of it. Analysis counts the whole wait and says
// c can miss; a run stops waiting at 3.5 ms (half the deadline) and runs on p's previous value: no
// miss, but every release an order timeout, a cycle of lag. Either way the file is wrong for this
// placement, and both say so.
TEST(CrossCpuChain, AWaitPastHalfTheDeadlineIsCanMissInAnalysisAndAnOrderTimeoutInARun) {
  const std::string yaml = split_chain(", deadline: 7ms, criticality: soft", true);
  const Analysed a = analyse(yaml);
  EXPECT_FALSE(a.result.feasible);
  EXPECT_EQ(a.of("c").verdict, analysis::Verdict::kCanMiss);
  EXPECT_EQ(a.of("c").reason,
            "response time 7.5 ms > deadline 7 ms; it waits up to 4.5 ms for p on another CPU, past half its "
            "deadline, where a run stops waiting and reads p's previous value (an order timeout): keep the chain "
            "on one CPU");

  auto s = testing::start_subsystem(yaml, testing::scheduling_registry());
  ASSERT_TRUE(s);
  s->run_for(100 * kMs);
  const auto c = testing::task_of(*s, "c").stats;
  EXPECT_EQ(c.cycles, 10u);
  EXPECT_EQ(c.order_timeouts, 10u) << "every release stops waiting at half the deadline";
  EXPECT_EQ(c.missed, 0u);
  EXPECT_EQ(c.response_max_ns, 6500 * kUs) << "3.5 ms of waiting, 1.5 ms of work, h1's 1 ms, 0.5 ms";
  EXPECT_GT(s->get("lagged")->at(0), 0.0) << "it read p's previous value";
}

TEST(CrossCpuChain, LeftToItselfPlacementKeepsTheChainOnOneCpuAndNobodyWaits) {
  const Analysed a = analyse(split_chain("", false));
  EXPECT_TRUE(a.result.feasible);
  EXPECT_EQ(a.result.cpu_of[0], a.result.cpu_of[2]) << "p and c on one CPU";
  EXPECT_NE(a.result.cpu_of[0], a.result.cpu_of[1]) << "hog0 (0.6) on the other";
  EXPECT_EQ(a.of("c").release_jitter_ns, 0);
}

}  // namespace
}  // namespace chimera
