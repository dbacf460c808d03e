// Costs of the state variable table, uncontended: one write or read of n doubles through the
// sequence protocol, the same copy under a std::mutex for comparison, and the per-cycle
// transfers of the paper's PID task (Figure 4). Run on a Release build.

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "chimera/svt/global_table.hpp"
#include "chimera/svt/local_table.hpp"

namespace chimera {
namespace {

GlobalTable make_table(const std::string& tag, const std::vector<VarSpec>& vars) {
  static int counter = 0;
  auto t = GlobalTable::create("bench" + std::to_string(::getpid()) + "_" + tag + std::to_string(counter++), vars);
  if (!t) {
    std::fprintf(stderr, "%s\n", t.error().message.c_str());
    std::abort();
  }
  return std::move(*t);
}

void set_bytes(benchmark::State& state, std::size_t per_iteration) {
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * per_iteration));
}

void BM_SvtWrite(benchmark::State& state) {
  const auto n = static_cast<std::uint32_t>(state.range(0));
  GlobalTable table = make_table("w", {{"x", {ElemType::kF64, n}}});
  std::vector<double> value(n, 1.0);
  for (auto _ : state) {
    table.write(0, value.data());
    benchmark::ClobberMemory();
  }
  set_bytes(state, n * sizeof(double));
}

void BM_SvtReadNew(benchmark::State& state) {
  const auto n = static_cast<std::uint32_t>(state.range(0));
  GlobalTable table = make_table("r", {{"x", {ElemType::kF64, n}}});
  std::vector<double> value(n, 1.0);
  table.write(0, value.data());
  for (auto _ : state) {
    // seen = 0: every read finds a newer value and copies it.
    benchmark::DoNotOptimize(table.read(0, value.data(), 0));
    benchmark::ClobberMemory();
  }
  set_bytes(state, n * sizeof(double));
}

void BM_SvtReadOld(benchmark::State& state) {
  const auto n = static_cast<std::uint32_t>(state.range(0));
  GlobalTable table = make_table("o", {{"x", {ElemType::kF64, n}}});
  std::vector<double> value(n, 1.0);
  table.write(0, value.data());
  for (auto _ : state) {
    // seen = current version: nothing to copy.
    benchmark::DoNotOptimize(table.read(0, value.data(), 1));
  }
}

/// The comparison: the same copy under a lock, as a naive shared variable would do it.
struct MutexVar {
  std::mutex mutex;
  std::vector<double> data;
};

void BM_MutexWrite(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  MutexVar var{{}, std::vector<double>(n)};
  std::vector<double> value(n, 1.0);
  for (auto _ : state) {
    std::lock_guard lock(var.mutex);
    std::memcpy(var.data.data(), value.data(), n * sizeof(double));
    benchmark::ClobberMemory();
  }
  set_bytes(state, n * sizeof(double));
}

void BM_MutexRead(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  MutexVar var{{}, std::vector<double>(n, 1.0)};
  std::vector<double> value(n);
  for (auto _ : state) {
    std::lock_guard lock(var.mutex);
    std::memcpy(value.data(), var.data.data(), n * sizeof(double));
    benchmark::ClobberMemory();
  }
  set_bytes(state, n * sizeof(double));
}

BENCHMARK(BM_SvtWrite)->Arg(1)->Arg(6)->Arg(36)->Arg(1024);
BENCHMARK(BM_SvtReadNew)->Arg(1)->Arg(6)->Arg(36)->Arg(1024);
BENCHMARK(BM_SvtReadOld)->Arg(1)->Arg(6)->Arg(36)->Arg(1024);
BENCHMARK(BM_MutexWrite)->Arg(1)->Arg(6)->Arg(36)->Arg(1024);
BENCHMARK(BM_MutexRead)->Arg(1)->Arg(6)->Arg(36)->Arg(1024);

// ---- the PID task of Figure 4 ---------------------------------------------------------------

constexpr VarShape kJoints{ElemType::kF64, 6};

struct Fig4 {
  GlobalTable global = make_table("fig4", {{"theta_d", kJoints},
                                           {"theta_dot_d", kJoints},
                                           {"theta_m", kJoints},
                                           {"theta_dot_m", kJoints},
                                           {"tau_r", kJoints},
                                           {"gains", {ElemType::kF64, 3}}});
  LocalTable generator =
      make({{"q_d", "theta_d", PortKind::kOutVar, kJoints}, {"qd_d", "theta_dot_d", PortKind::kOutVar, kJoints}});
  LocalTable robot = make({{"tau", "tau_r", PortKind::kInVar, kJoints},
                           {"q", "theta_m", PortKind::kOutVar, kJoints},
                           {"qd", "theta_dot_m", PortKind::kOutVar, kJoints}});
  LocalTable pid = make({{"q_d", "theta_d", PortKind::kInVar, kJoints},
                         {"qd_d", "theta_dot_d", PortKind::kInVar, kJoints},
                         {"q", "theta_m", PortKind::kInVar, kJoints},
                         {"qd", "theta_dot_m", PortKind::kInVar, kJoints},
                         {"gains", "gains", PortKind::kInConst, {ElemType::kF64, 3}},
                         {"tau", "tau_r", PortKind::kOutVar, kJoints}});

  LocalTable make(const std::vector<PortBinding>& ports) {
    auto t = LocalTable::create(global, ports);
    if (!t) {
      std::fprintf(stderr, "%s\n", t.error().message.c_str());
      std::abort();
    }
    return std::move(*t);
  }
};

void BM_PidPullInVarsNothingNew(benchmark::State& state) {
  Fig4 f;
  f.generator.push_out_vars(0);
  f.robot.push_out_vars(0);
  f.pid.pull_in_vars();
  for (auto _ : state) {
    f.pid.pull_in_vars();  // four version checks, no copy
    benchmark::ClobberMemory();
  }
}

void BM_PidPushOutVars(benchmark::State& state) {
  Fig4 f;
  for (auto _ : state) {
    f.pid.push_out_vars(0);  // tau_r
    benchmark::ClobberMemory();
  }
}

void BM_Fig4CycleTransfers(benchmark::State& state) {
  Fig4 f;
  for (auto _ : state) {
    // One period of all three tasks: 4 writes by the producers, 4 new reads and 1 write by the
    // PID, 1 new read by the robot.
    f.generator.push_out_vars(0);
    f.robot.push_out_vars(0);
    f.pid.pull_in_vars();
    f.pid.push_out_vars(0);
    f.robot.pull_in_vars();
    benchmark::ClobberMemory();
  }
}

BENCHMARK(BM_PidPullInVarsNothingNew);
BENCHMARK(BM_PidPushOutVars);
BENCHMARK(BM_Fig4CycleTransfers);

}  // namespace
}  // namespace chimera

BENCHMARK_MAIN();
