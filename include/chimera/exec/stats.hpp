#pragma once
// Per-task timing statistics, gathered on the real-time path without allocation: counters and
// fixed log-scale histograms written by the task's thread and read by anyone.

#include <array>
#include <atomic>
#include <cstdint>
#include <utility>
#include <vector>

namespace chimera {

/// A histogram of nanosecond values with buckets of about 3% width from 1 ns to about 68 s.
/// One writer (the task's thread), any number of readers. Real-time safe.
class LatencyHistogram {
 public:
  static constexpr int kSubBuckets = 32;  // per power of two: about 3% resolution
  static constexpr int kPowers = 36;      // 2^36 ns ~ 68 s
  static constexpr int kBuckets = kSubBuckets * kPowers;

  void record(std::int64_t ns) noexcept;
  /// The buckets that hold records: (upper bound in ns, count), ascending. Not real-time safe.
  [[nodiscard]] std::vector<std::pair<std::int64_t, std::uint64_t>> nonempty_buckets() const;
  /// The value below which `fraction` of the records fall (bucket upper bound). 0 when empty.
  [[nodiscard]] std::int64_t percentile(double fraction) const noexcept;
  [[nodiscard]] std::uint64_t count() const noexcept;
  [[nodiscard]] std::int64_t max() const noexcept;
  void reset() noexcept;

  static int bucket_of(std::int64_t ns) noexcept;
  static std::int64_t upper_bound_of(int bucket) noexcept;

 private:
  // Single writer: plain load+store with relaxed order is enough; readers only need each value
  // to be untorn, not ordered with the others.
  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::int64_t> max_{0};
};

/// A copy of a task's figures, for the timing table and --stats-json.
struct TaskStatsSnapshot {
  /// Which clock the exec_* figures are in: false, the host's (real clock: the cycle's CPU or
  /// wall time); true, simulated (virtual clock: virtual_exec plus what the module charged).
  bool exec_simulated = false;
  std::uint64_t cycles = 0;
  std::uint64_t missed = 0;    // deadlines missed: cycles that ended late, plus skipped releases
  std::uint64_t overruns = 0;  // cycles that ran longer than the task's wcet budget
  std::uint64_t skipped = 0;   // releases not run at all (late: skip), each also a missed deadline
  std::int64_t exec_mean_ns = 0;
  std::int64_t exec_p50_ns = 0;
  std::int64_t exec_p99_ns = 0;
  std::int64_t exec_max_ns = 0;
  /// The host's time the cycles took: the exec_* figures' own on the real clock; on the virtual
  /// clock what the framework and the module spent on the host while simulated time stood still.
  std::int64_t host_exec_mean_ns = 0;
  std::int64_t host_exec_max_ns = 0;
  std::int64_t latency_p50_ns = 0;  // release to start of cycle
  std::int64_t latency_p99_ns = 0;
  std::int64_t latency_max_ns = 0;
  std::int64_t response_p99_ns = 0;  // release to end of cycle, on the subsystem's clock
  std::int64_t response_max_ns = 0;
  /// Profiles: (bucket upper bound in ns, count) of the buckets that hold records.
  std::vector<std::pair<std::int64_t, std::uint64_t>> exec_histogram;
  std::vector<std::pair<std::int64_t, std::uint64_t>> latency_histogram;
  /// Cycles that started without a same-rate producer's value of the same release because the
  /// producer kept them waiting past the bound (real clock only; see docs/architecture.md).
  std::uint64_t order_timeouts = 0;
  /// --rt-check: allocations made inside the task's on(), cycle(), off() and sync() (0 without
  /// the check, which counts nothing).
  std::uint64_t rt_violations = 0;
};

/// Everything the framework counts for one task. Written only by the task's thread.
class TaskStats {
 public:
  /// One finished cycle: release to start, execution time, release to end. Real-time safe.
  void record_cycle(std::int64_t latency_ns, std::int64_t exec_ns, std::int64_t response_ns, bool missed,
                    bool overrun) noexcept;
  /// The host's time of the cycle just recorded, when record_cycle() was given its simulated
  /// time (virtual clock): from then on the snapshot's exec figures are simulated. Real-time safe.
  void record_host_exec(std::int64_t ns) noexcept;
  /// `n` releases skipped without running (each a missed deadline). Real-time safe.
  void record_skipped(std::uint64_t n) noexcept;
  /// A precedence wait gave up. Real-time safe.
  void record_order_timeout() noexcept;
  /// An allocation on the real-time path (--rt-check); true for the first one. Real-time safe.
  bool record_rt_allocation() noexcept;
  /// A copy of every figure, histograms included (it allocates). Not real-time safe.
  [[nodiscard]] TaskStatsSnapshot snapshot() const;
  void reset() noexcept;

 private:
  LatencyHistogram latency_;
  LatencyHistogram exec_;
  LatencyHistogram response_;
  std::atomic<std::uint64_t> cycles_{0};
  std::atomic<std::uint64_t> missed_{0};
  std::atomic<std::uint64_t> overruns_{0};
  std::atomic<std::uint64_t> skipped_{0};
  std::atomic<std::uint64_t> order_timeouts_{0};
  std::atomic<std::uint64_t> rt_allocations_{0};
  std::atomic<std::int64_t> exec_sum_ns_{0};
  std::atomic<std::int64_t> exec_max_ns_{0};
  std::atomic<bool> exec_simulated_{false};
  std::atomic<std::uint64_t> host_cycles_{0};
  std::atomic<std::int64_t> host_exec_sum_ns_{0};
  std::atomic<std::int64_t> host_exec_max_ns_{0};
};

}  // namespace chimera
