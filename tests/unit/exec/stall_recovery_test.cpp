// Recovery from a stall, exactly, on the virtual clock: a five-task chain at 1 ms (the shape of
// examples/fig4_filtered_chain.yaml) and a stall injected by cpu_load "hogs", one per CPU, more
// urgent than the chain (rm: a 0.5 ms period), whose 200th cycle burns 40 ms of simulated time:
// the CPU is taken from 99.5 to 139.5 ms, as a VM stall or a SCHED_FIFO hog would take it on the
// real clock (bench/stall_bench.cpp measures that). The policy is docs/scheduling.md's "After a
// stall": under late: run every late release runs, under late: skip the ones whose deadline has
// passed are skipped, and either way every task is back on time at the first release after the
// stall; a consumer never waits for a producer that is behind, so a stall of one CPU costs a
// consumer on the other at most one wait (one order timeout), not one per period.

#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/run_subsystem.hpp"
#include "support/trace_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kStallFrom = 99'500'000;  // the hogs' 200th release
constexpr std::int64_t kStallTo = kStallFrom + 40 * kMs;
constexpr std::int64_t kRunFor = 200 * kMs;  // releases 0 .. 199 ms of each chain task

/// One job of a link: its release, when it started, and the release its input came from (the
/// same one if the same-rate rule was kept; -1: no input yet, or the first link).
struct LinkJob {
  std::int64_t release_ns = 0;
  std::int64_t start_ns = 0;
  std::int64_t input_release_ns = -1;
};

std::map<std::string, std::vector<LinkJob>>& link_jobs() {
  static std::map<std::string, std::vector<LinkJob>> jobs;
  return jobs;
}

/// A link of the chain: out = the release of its cycle; reads the release its producer stamped
/// (the first link has no input). Recovers from timing faults, so that a stall's misses are
/// counted and the task stays ON. Allocates in cycle(): tests only.
class StallLink : public Module {
 public:
  static constexpr const char* kName = "stall_link";
  static constexpr const char* kSummary = "a chain link that stamps its release";
  static constexpr const char* kDoc = "out = release of the cycle; records whether in was of the same release";
  static void declare(Declarations& d, const Params& p) {
    if (!p.flag("source")) d.in_var<std::int64_t>("in", Dim::fixed(1), "the producer's release");
    d.out_var<std::int64_t>("out", Dim::fixed(1), "this cycle's release");
    d.param("source", false, "", "first link: no input");
  }

 protected:
  Status init(InitContext& ctx) override {
    name_ = std::string(ctx.task_name());
    timing_ = &ctx.timing();
    source_ = ctx.params().flag("source");
    if (!source_) in_ = ctx.in<std::int64_t>("in");
    out_ = ctx.out<std::int64_t>("out");
    return Status::ok();
  }
  Status cycle() override {
    const std::int64_t release = timing_->release_ns;
    const std::int64_t input = !source_ && in_.has_data() ? in_[0] : -1;
    link_jobs()[name_].push_back({release, timing_->start_ns, source_ ? release : input});
    out_[0] = release;
    return Status::ok();
  }
  Status error() override { return Status::ok(); }  // a late cycle is only late

 private:
  std::string name_;
  const CycleTiming* timing_ = nullptr;
  bool source_ = false;
  In<std::int64_t> in_;
  Out<std::int64_t> out_;
};

const Registry& stall_registry() {
  static Registry r = [] {
    Registry reg;
    for (const ModuleInfo* m : testing::scheduling_registry().list()) (void)reg.add(*m);
    (void)reg.add(testing::info_of<StallLink>());
    return reg;
  }();
  return r;
}

struct Chain {
  std::vector<int> cpus;     // of the links a..e
  std::vector<int> hogs;     // CPUs the stall takes
  std::string late = "run";  // the links' late:
};

const std::vector<std::string> kLinks = {"a", "b", "c", "d", "e"};

std::unique_ptr<Subsystem> run_chain(const Chain& chain) {
  link_jobs().clear();
  std::string yaml = "subsystem: stall\nscheduler: rm\ncpus: [0, 1]\ntasks:\n";
  for (const int cpu : chain.hogs)
    yaml += "  - {name: hog" + std::to_string(cpu) + ", module: cpu_load, period: 500us, cpu: " + std::to_string(cpu) +
            ", criticality: soft, params: {overrun_every: 200, overrun: 0.04}}\n";
  for (std::size_t i = 0; i < kLinks.size(); ++i) {
    yaml += "  - {name: " + kLinks[i] + ", module: stall_link, period: 1ms, cpu: " + std::to_string(chain.cpus[i]) +
            ", late: " + chain.late + ", ";
    yaml += i == 0 ? "params: {source: true}, rename: {out: v0}}\n"
                   : "rename: {in: v" + std::to_string(i - 1) + ", out: v" + std::to_string(i) + "}}\n";
  }
  auto s = testing::start_subsystem(yaml, stall_registry());
  if (s) s->run_for(kRunFor);
  return s;
}

/// The first release from which every job of `task` started at its release: back on time.
std::int64_t on_time_from(const std::string& task) {
  const auto& jobs = link_jobs()[task];
  std::int64_t from = 0;
  for (const auto& j : jobs)
    if (j.start_ns != j.release_ns) from = j.release_ns + kMs;
  return from;
}

/// Jobs that read an older release's value than their own (a cycle of lag).
int lagged_inputs(const std::string& task) {
  int n = 0;
  for (const auto& j : link_jobs()[task]) n += j.input_release_ns < j.release_ns ? 1 : 0;
  return n;
}

/// Jobs that read a newer release's value than their own: a late job whose producer was ahead.
int newer_inputs(const std::string& task) {
  int n = 0;
  for (const auto& j : link_jobs()[task]) n += j.input_release_ns > j.release_ns ? 1 : 0;
  return n;
}

// Releases 100 .. 138 ms have their deadline (release + 1 ms) at or before 139.5 ms, when the
// stall ends: 39 misses. Release 139 runs at 139.5 ms, late but within its deadline.
constexpr std::uint64_t kMissedInStall = 39;

void expect_recovered_in_order(Subsystem& s, const Chain& chain) {
  for (const auto& name : kLinks) {
    SCOPED_TRACE(name);
    const auto t = testing::task_of(s, name);
    EXPECT_EQ(t.state, TaskState::kOn);
    EXPECT_EQ(t.stats.missed, kMissedInStall);
    EXPECT_EQ(t.stats.order_timeouts, 0U) << "every producer was as late as its consumer: no wait gave up";
    EXPECT_EQ(on_time_from(name), 140 * kMs) << "back on time at the first release after the stall";
    EXPECT_EQ(lagged_inputs(name), 0) << "the chain caught up in data-flow order";
    EXPECT_EQ(newer_inputs(name), 0);
    if (chain.late == "run") {
      EXPECT_EQ(t.stats.skipped, 0U);
      EXPECT_EQ(t.stats.cycles, 200U) << "late: run runs every release";
    } else {
      EXPECT_EQ(t.stats.skipped, kMissedInStall);
      EXPECT_EQ(t.stats.cycles, 200U - kMissedInStall) << "late: skip runs none whose deadline has passed";
    }
  }
}

TEST(StallRecovery, AChainOnOneCpuIsBackOnTimeAtTheFirstReleaseAfterTheStallUnderLateRun) {
  auto s = run_chain({{0, 0, 0, 0, 0}, {0}, "run"});
  ASSERT_TRUE(s);
  expect_recovered_in_order(*s, {{0, 0, 0, 0, 0}, {0}, "run"});
  // The 39 late releases ran one after another at 139.5 ms, in order.
  const auto& a = link_jobs()["a"];
  ASSERT_EQ(a.size(), 200U);
  EXPECT_EQ(a[100].start_ns, kStallTo);
  EXPECT_EQ(a[139].start_ns, kStallTo);
}

TEST(StallRecovery, AChainOnOneCpuSkipsWhatIsTooLateUnderLateSkip) {
  const Chain chain{{0, 0, 0, 0, 0}, {0}, "skip"};
  auto s = run_chain(chain);
  ASSERT_TRUE(s);
  expect_recovered_in_order(*s, chain);
}

TEST(StallRecovery, AChainSplitAcrossCpusRecoversAsFastWhenBothCpusStall) {
  for (const std::string late : {"run", "skip"}) {
    SCOPED_TRACE(late);
    const Chain chain{{0, 1, 0, 1, 0}, {0, 1}, late};
    auto s = run_chain(chain);
    ASSERT_TRUE(s);
    expect_recovered_in_order(*s, chain);
  }
}

TEST(StallRecovery, AStallOfOneCpuCostsAConsumerOnTheOtherOneWaitNotOnePerPeriod) {
  // CPU 1 (b and d) stalls; a, c and e on CPU 0 go on. c waits for b's release 100 until its
  // bound (half its deadline), once; from release 101 on b is behind (100 still to run) and c
  // runs on time with b's latest value. Under the rule before (wait for a producer that will get
  // to the release eventually), c and e waited half a period every period of the stall. Every
  // job that ran without its producer's value of its release is counted (order_timeouts).
  for (const std::string late : {"run", "skip"}) {
    SCOPED_TRACE(late);
    auto s = run_chain({{0, 1, 0, 1, 0}, {1}, late});
    ASSERT_TRUE(s);
    for (const std::string name : {"c", "e"}) {
      SCOPED_TRACE(name);
      const auto t = testing::task_of(*s, name);
      EXPECT_EQ(t.stats.missed, 0U) << "0.5 ms late once, within its deadline";
      EXPECT_EQ(t.stats.cycles, 200U);
      EXPECT_EQ(on_time_from(name), 101 * kMs) << "one wait, at release 100";
      EXPECT_EQ(link_jobs()[name][100].start_ns, 100 * kMs + 500'000);
      // Releases 100 .. 139: the producer on the stalled CPU had not run them.
      EXPECT_EQ(lagged_inputs(name), 40);
      EXPECT_EQ(t.stats.order_timeouts, 40U) << "each of them counted";
    }
    for (const std::string name : {"b", "d"}) {
      SCOPED_TRACE(name);
      const auto t = testing::task_of(*s, name);
      EXPECT_EQ(t.state, TaskState::kOn);
      EXPECT_EQ(t.stats.missed, kMissedInStall);
      EXPECT_EQ(t.stats.order_timeouts, 0U) << "its producer on CPU 0 was ahead: nothing to wait for";
      EXPECT_EQ(on_time_from(name), 140 * kMs);
      EXPECT_EQ(lagged_inputs(name), 0);
      // Under late: run its late jobs 100 .. 138 read the producer's newest value (release 139).
      EXPECT_EQ(newer_inputs(name), late == "run" ? 39 : 0);
    }
    EXPECT_EQ(testing::task_of(*s, "a").stats.missed, 0U);
  }
}

}  // namespace
}  // namespace chimera
