#include "chimera/exec/stats.hpp"

#include <algorithm>
#include <bit>

namespace chimera {

// Buckets: values below kSubBuckets have one bucket each; above, each power of two is split
// into kSubBuckets equal parts (about 3% wide). Bucket math is shifts only: real-time safe.
int LatencyHistogram::bucket_of(std::int64_t ns) noexcept {
  if (ns < kSubBuckets) return ns < 0 ? 0 : static_cast<int>(ns);
  const auto v = static_cast<std::uint64_t>(ns);
  const int power = static_cast<int>(std::bit_width(v)) - 1;  // v in [2^power, 2^(power+1))
  const int shift = power - 5;                                // 5 = log2(kSubBuckets)
  const int sub = static_cast<int>((v >> shift) - kSubBuckets);
  const int bucket = (shift + 1) * kSubBuckets + sub;
  return std::min(bucket, kBuckets - 1);
}

std::int64_t LatencyHistogram::upper_bound_of(int bucket) noexcept {
  if (bucket < kSubBuckets) return bucket;
  const int shift = bucket / kSubBuckets - 1;
  const int sub = bucket % kSubBuckets;
  return (static_cast<std::int64_t>(kSubBuckets + sub + 1) << shift) - 1;
}

void LatencyHistogram::record(std::int64_t ns) noexcept {
  auto& b = buckets_[static_cast<std::size_t>(bucket_of(ns))];
  // Single writer: load+store instead of a locked read-modify-write; relaxed because readers
  // need each counter untorn, not ordered against the others.
  b.store(b.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  count_.store(count_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  if (ns > max_.load(std::memory_order_relaxed)) max_.store(ns, std::memory_order_relaxed);
}

std::int64_t LatencyHistogram::percentile(double fraction) const noexcept {
  const std::uint64_t total = count_.load(std::memory_order_relaxed);  // a snapshot; may lag
  if (total == 0) return 0;
  const auto rank = static_cast<std::uint64_t>(fraction * static_cast<double>(total - 1)) + 1;
  std::uint64_t seen = 0;
  for (int i = 0; i < kBuckets; ++i) {
    seen += buckets_[static_cast<std::size_t>(i)].load(std::memory_order_relaxed);  // untorn is enough
    if (seen >= rank) return std::min(upper_bound_of(i), max());
  }
  return max();
}

std::vector<std::pair<std::int64_t, std::uint64_t>> LatencyHistogram::nonempty_buckets() const {
  std::vector<std::pair<std::int64_t, std::uint64_t>> out;
  for (int i = 0; i < kBuckets; ++i) {
    const std::uint64_t n = buckets_[static_cast<std::size_t>(i)].load(std::memory_order_relaxed);  // untorn is enough
    if (n != 0) out.emplace_back(upper_bound_of(i), n);
  }
  return out;
}

std::uint64_t LatencyHistogram::count() const noexcept { return count_.load(std::memory_order_relaxed); }
std::int64_t LatencyHistogram::max() const noexcept { return max_.load(std::memory_order_relaxed); }

void LatencyHistogram::reset() noexcept {
  for (auto& b : buckets_) b.store(0, std::memory_order_relaxed);  // only while the writer is idle
  count_.store(0, std::memory_order_relaxed);
  max_.store(0, std::memory_order_relaxed);
}

namespace {
// Single writer (the task's thread); relaxed: each figure is read on its own.
void bump(std::atomic<std::uint64_t>& counter, std::uint64_t n = 1) noexcept {
  counter.store(counter.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
}
}  // namespace

void TaskStats::record_cycle(std::int64_t latency_ns, std::int64_t exec_ns, std::int64_t response_ns, bool missed,
                             bool overrun) noexcept {
  latency_.record(latency_ns);
  exec_.record(exec_ns);
  response_.record(response_ns);
  bump(cycles_);
  if (missed) bump(missed_);
  if (overrun) bump(overruns_);
  exec_sum_ns_.store(exec_sum_ns_.load(std::memory_order_relaxed) + exec_ns, std::memory_order_relaxed);
  if (exec_ns > exec_max_ns_.load(std::memory_order_relaxed)) exec_max_ns_.store(exec_ns, std::memory_order_relaxed);
}

void TaskStats::record_host_exec(std::int64_t ns) noexcept {
  exec_simulated_.store(true, std::memory_order_relaxed);  // read on its own, like every figure
  bump(host_cycles_);
  host_exec_sum_ns_.store(host_exec_sum_ns_.load(std::memory_order_relaxed) + ns, std::memory_order_relaxed);
  if (ns > host_exec_max_ns_.load(std::memory_order_relaxed)) host_exec_max_ns_.store(ns, std::memory_order_relaxed);
}

void TaskStats::record_skipped(std::uint64_t n) noexcept {
  bump(skipped_, n);
  bump(missed_, n);
}

void TaskStats::record_order_timeout() noexcept { bump(order_timeouts_); }

bool TaskStats::record_rt_allocation() noexcept {
  const std::uint64_t before = rt_allocations_.load(std::memory_order_relaxed);  // single writer, as bump()
  bump(rt_allocations_);
  return before == 0;
}

TaskStatsSnapshot TaskStats::snapshot() const {
  TaskStatsSnapshot s;
  s.cycles = cycles_.load(std::memory_order_relaxed);  // figures may be one cycle apart: fine for a table
  s.missed = missed_.load(std::memory_order_relaxed);
  s.overruns = overruns_.load(std::memory_order_relaxed);
  s.skipped = skipped_.load(std::memory_order_relaxed);
  const std::int64_t sum = exec_sum_ns_.load(std::memory_order_relaxed);
  s.exec_mean_ns = s.cycles != 0 ? sum / static_cast<std::int64_t>(s.cycles) : 0;
  s.exec_p50_ns = exec_.percentile(0.50);
  s.exec_p99_ns = exec_.percentile(0.99);
  s.exec_max_ns = exec_max_ns_.load(std::memory_order_relaxed);
  s.exec_simulated = exec_simulated_.load(std::memory_order_relaxed);
  if (s.exec_simulated) {
    const std::uint64_t host_cycles = host_cycles_.load(std::memory_order_relaxed);
    const std::int64_t host_sum = host_exec_sum_ns_.load(std::memory_order_relaxed);
    s.host_exec_mean_ns = host_cycles != 0 ? host_sum / static_cast<std::int64_t>(host_cycles) : 0;
    s.host_exec_max_ns = host_exec_max_ns_.load(std::memory_order_relaxed);
  } else {
    s.host_exec_mean_ns = s.exec_mean_ns;
    s.host_exec_max_ns = s.exec_max_ns;
  }
  s.latency_p50_ns = latency_.percentile(0.50);
  s.latency_p99_ns = latency_.percentile(0.99);
  s.latency_max_ns = latency_.max();
  s.response_p99_ns = response_.percentile(0.99);
  s.response_max_ns = response_.max();
  s.exec_histogram = exec_.nonempty_buckets();
  s.latency_histogram = latency_.nonempty_buckets();
  s.order_timeouts = order_timeouts_.load(std::memory_order_relaxed);
  s.rt_violations = rt_allocations_.load(std::memory_order_relaxed);
  return s;
}

void TaskStats::reset() noexcept {
  latency_.reset();
  exec_.reset();
  response_.reset();
  cycles_.store(0, std::memory_order_relaxed);  // only while the writer is idle
  missed_.store(0, std::memory_order_relaxed);
  overruns_.store(0, std::memory_order_relaxed);
  skipped_.store(0, std::memory_order_relaxed);
  order_timeouts_.store(0, std::memory_order_relaxed);
  rt_allocations_.store(0, std::memory_order_relaxed);
  exec_sum_ns_.store(0, std::memory_order_relaxed);
  exec_max_ns_.store(0, std::memory_order_relaxed);
  exec_simulated_.store(false, std::memory_order_relaxed);
  host_cycles_.store(0, std::memory_order_relaxed);
  host_exec_sum_ns_.store(0, std::memory_order_relaxed);
  host_exec_max_ns_.store(0, std::memory_order_relaxed);
}

}  // namespace chimera
