// Framework cost per cycle of the PID task of Figure 4, without the kernel's wake-up: what
// Task::begin_job / end_job do around the module's cycle() (pull four 6-double in-vars, push tau_r,
// two clock reads, statistics), measured with a module that has pid_joint's ports and an empty
// cycle (bench_null_pid). Each iteration first writes the four inputs, as the producers would,
// so every pull copies new values; BM_ProducerWrites alone is subtracted by bench/run.py:
//   cycle_overhead_ns = BM_PidCycleFramework - BM_ProducerWrites.
// BM_PidCycleReal runs the real pid_joint for comparison. BM_PidCycleRecorded is the framework's
// cycle with the flight recorder on (docs/flight-recorder.md): tau_r's value and the cycle's
// timing record written into rings, as `chimera run` does by default; bench/run.py reports
//   flight_recorder_cost_ns = BM_PidCycleRecorded - BM_PidCycleFramework.
// BM_PidCycleInputsFromOtherCpu is the framework's cycle when the four inputs were just written
// on the other CPU, as for a task whose producers run there (a module process's PID of
// process_bench): each cycle alone is timed, after a thread pinned to the other CPU has written
// them; bench/run.py reports it as cycle_overhead_inputs_from_other_cpu_ns.

#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "chimera/core/history_rings.hpp"
#include "chimera/svt/global_table.hpp"
#include "common/bench_util.hpp"
#include "exec/task.hpp"

namespace chimera::bench {
namespace {

struct NoFlags final : SubsystemFlags {
  [[nodiscard]] bool illegal_configuration() const noexcept override { return false; }
};

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "cycle_bench: %s\n", what.c_str());
  std::abort();
}

/// Figure 4's variables in a global table, and one task bound to them.
class PidFixture {
 public:
  explicit PidFixture(const std::string& module, bool recorded = false) {
    const std::string yaml = fmt::format(
        "subsystem: bench_cycle\nconstants:\n  ndof: 6\ntasks:\n  - name: pid\n    module: {}\n    period: 1ms\n"
        "configurations:\n  c: [pid]\n",
        module);
    auto spec = load_subsystem_text(yaml, "cycle_bench.yaml", Registry::global());
    if (!spec) die(spec.error().message);
    spec_ = std::make_unique<SubsystemSpec>(std::move(*spec));
    resolution_ = std::make_unique<Resolution>(resolve_subsystem(*spec_, Registry::global()));
    auto table =
        GlobalTable::create(fmt::format("bench_cycle_{}_{}", ::getpid(), counter_++), resolution_->subsystem.variables);
    if (!table) die(table.error().message);
    table_ = std::make_unique<GlobalTable>(std::move(*table));
    const double ndof = 6;
    table_->write(*table_->find("ndof"), &ndof);
    for (const char* v : {"theta_d", "dtheta_d", "theta_m", "dtheta_m"}) inputs_[n_inputs_++] = *table_->find(v);
    task_ = std::make_unique<Task>(resolution_->subsystem.tasks.front(), *table_, flags_);
    if (recorded) {
      // 10 s at 1 kHz, as the recorder keeps by default: a ring for the task's one output and
      // one for its cycles, sized as src/control/flight_recorder.cpp sizes them.
      constexpr std::uint32_t kRecords = 10'000;
      ring_of_var_.assign(table_->size(), -1);
      const VarIndex tau = *table_->find("tau_r");
      ring_of_var_[tau] = static_cast<std::int32_t>(rings_.add(kRecords, 6 * sizeof(double)));
      const auto timing = static_cast<std::int32_t>(rings_.add(kRecords, sizeof(CycleRecord)));
      rings_.allocate();
      task_->keep_history(&rings_, timing, ring_of_var_);
    }
    if (auto r = task_->apply(Signal::kSpawn, 0); !r) die(r.error().message);
    if (auto r = task_->apply(Signal::kOn, 0); !r) die(r.error().message);
  }
  PidFixture(const PidFixture&) = delete;
  PidFixture& operator=(const PidFixture&) = delete;
  ~PidFixture() { (void)task_->apply(Signal::kKill, 0); }

  /// The producers' part of a period: four new 6-double values.
  void write_inputs() noexcept {
    values_[0] += 1e-3;
    for (std::size_t i = 0; i < n_inputs_; ++i) table_->write(inputs_[i], values_.data());
  }
  void cycle() noexcept {
    // What the real executive does around a cycle: begin the job, end it (measured).
    (void)task_->begin_job(release_, release_);
    (void)task_->end_job(release_, -1);
    release_ += 1'000'000;
  }

 private:
  static inline int counter_ = 0;
  NoFlags flags_;
  std::unique_ptr<SubsystemSpec> spec_;
  std::unique_ptr<Resolution> resolution_;
  std::unique_ptr<GlobalTable> table_;
  HistoryRings rings_;                     // outlives the task, which writes into it
  std::vector<std::int32_t> ring_of_var_;  // per variable of the table
  std::unique_ptr<Task> task_;
  std::array<VarIndex, 4> inputs_{};
  std::size_t n_inputs_ = 0;
  std::array<double, 6> values_{0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  std::int64_t release_ = 0;
};

void BM_ProducerWrites(benchmark::State& state) {
  PidFixture f("bench_null_pid");
  for (auto _ : state) {
    f.write_inputs();
    benchmark::ClobberMemory();
  }
}

void BM_PidCycleFramework(benchmark::State& state) {
  PidFixture f("bench_null_pid");
  for (auto _ : state) {
    f.write_inputs();
    f.cycle();
    benchmark::ClobberMemory();
  }
}

void BM_PidCycleReal(benchmark::State& state) {
  PidFixture f("pid_joint");
  for (auto _ : state) {
    f.write_inputs();
    f.cycle();
    benchmark::ClobberMemory();
  }
}

void BM_PidCycleRecorded(benchmark::State& state) {
  PidFixture f("bench_null_pid", /*recorded=*/true);
  for (auto _ : state) {
    f.write_inputs();
    f.cycle();
    benchmark::ClobberMemory();
  }
}

void BM_PidCycleInputsFromOtherCpu(benchmark::State& state) {
  const unsigned cpus = std::thread::hardware_concurrency();
  if (cpus < 2 || !pin_to_cpu(0)) {
    state.SkipWithError("needs two CPUs and the right to pin to them");
    return;
  }
  PidFixture f("bench_null_pid");
  // The producer's turn and the consumer's, each on a line of its own, so that the handshake
  // does not share a line with what is measured.
  alignas(64) std::atomic<std::uint64_t> asked{0};
  alignas(64) std::atomic<std::uint64_t> written{0};
  std::jthread producer([&](const std::stop_token& stop) {
    (void)pin_to_cpu(static_cast<int>(cpus - 1));
    std::uint64_t turn = 0;
    while (!stop.stop_requested()) {
      if (asked.load(std::memory_order_acquire) == turn) continue;  // acquire: after the consumer's cycle
      ++turn;
      f.write_inputs();
      written.store(turn, std::memory_order_release);  // release: the writes before the consumer's cycle
    }
  });
  std::uint64_t turn = 0;
  for (auto _ : state) {
    asked.store(++turn, std::memory_order_release);            // release: the last cycle's reads are done
    while (written.load(std::memory_order_acquire) != turn) {  // acquire: pairs with the producer
    }
    const auto begin = std::chrono::steady_clock::now();
    f.cycle();
    const auto end = std::chrono::steady_clock::now();
    benchmark::ClobberMemory();
    state.SetIterationTime(std::chrono::duration<double>(end - begin).count());
  }
  producer.request_stop();
  producer.join();
}

BENCHMARK(BM_ProducerWrites);
BENCHMARK(BM_PidCycleFramework);
BENCHMARK(BM_PidCycleReal);
BENCHMARK(BM_PidCycleRecorded);
BENCHMARK(BM_PidCycleInputsFromOtherCpu)->UseManualTime();

}  // namespace
}  // namespace chimera::bench

BENCHMARK_MAIN();
