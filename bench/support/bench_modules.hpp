#pragma once
// Modules that exist only for the benchmarks: they do (almost) nothing in cycle(), so that what
// is measured is the framework around them. Registered in the process that includes this header.

#include <atomic>
#include <cstdint>
#include <vector>

#include "chimera/exec/clock.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::bench {

/// Where bench_stamp writes: (monotonic time at the start of cycle(), nominal release), one pair
/// a cycle, preallocated before the run so that cycle() never allocates.
struct StampLog {
  std::vector<std::int64_t> start_ns;
  std::vector<std::int64_t> release_ns;
  std::atomic<std::size_t> count{0};
  void reserve(std::size_t n) {
    start_ns.assign(n, 0);
    release_ns.assign(n, 0);
    count.store(0, std::memory_order_relaxed);  // relaxed: set before any task thread starts
  }
};

inline StampLog& stamp_log() {
  static StampLog log;
  return log;
}

/// Records when each cycle starts against its nominal release: a release-latency probe.
class BenchStamp final : public Module {
 public:
  static constexpr const char* kName = "bench_stamp";
  static constexpr const char* kSummary = "benchmark probe: stamps the start of every cycle";
  static constexpr const char* kDoc = "Records monotonic time and nominal release of each cycle (bench only).";
  static void declare(Declarations& /*d*/, const Params& /*p*/) {}

 protected:
  Status init(InitContext& ctx) override {
    timing_ = &ctx.timing();
    return Status::ok();
  }
  Status cycle() override {
    const std::int64_t now = monotonic_ns();
    StampLog& log = stamp_log();
    // Relaxed: one task writes; the reader looks after the task's thread has been joined.
    const std::size_t i = log.count.load(std::memory_order_relaxed);
    if (i < log.start_ns.size()) {
      log.start_ns[i] = now;
      log.release_ns[i] = timing_->release_ns;
      log.count.store(i + 1, std::memory_order_relaxed);
    }
    return Status::ok();
  }

 private:
  const CycleTiming* timing_ = nullptr;
};

/// A task that does nothing: all its cost is the framework's.
class BenchIdle final : public Module {
 public:
  static constexpr const char* kName = "bench_idle";
  static constexpr const char* kSummary = "benchmark: an empty cycle";
  static constexpr const char* kDoc = "Does nothing (bench only).";
  static void declare(Declarations& /*d*/, const Params& /*p*/) {}
};

/// The PID joint controller's ports (Figure 4) with an empty cycle: what the framework does for
/// the PID task each cycle, without the PID law itself.
class BenchNullPid final : public Module {
 public:
  static constexpr const char* kName = "bench_null_pid";
  static constexpr const char* kSummary = "benchmark: pid_joint's ports, empty cycle";
  static constexpr const char* kDoc = "The ports of pid_joint and no computation (bench only).";
  static void declare(Declarations& d, const Params& /*p*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("theta_d", Dim::of("ndof"), "desired joint positions, rad");
    d.in_var("dtheta_d", Dim::of("ndof"), "desired joint velocities, rad/s");
    d.in_var("theta_m", Dim::of("ndof"), "measured joint positions, rad");
    d.in_var("dtheta_m", Dim::of("ndof"), "measured joint velocities, rad/s");
    d.out_var("tau_r", Dim::of("ndof"), "reference joint torques, N*m");
  }
};

/// A producer for the switch benchmark: out-var `stamp` = the release of the cycle that wrote it.
class BenchStamper final : public Module {
 public:
  static constexpr const char* kName = "bench_stamper";
  static constexpr const char* kSummary = "benchmark: stamps each output with its release";
  static constexpr const char* kDoc = "stamp = the nominal release of the cycle (bench only).";
  static void declare(Declarations& d, const Params& /*p*/) {
    d.out_var<std::int64_t>("stamp", Dim::fixed(1), "release of the cycle that wrote it, ns");
  }

 protected:
  Status init(InitContext& ctx) override {
    timing_ = &ctx.timing();
    stamp_ = ctx.out<std::int64_t>("stamp");
    return Status::ok();
  }
  Status cycle() override {
    stamp_[0] = timing_->release_ns;
    return Status::ok();
  }

 private:
  const CycleTiming* timing_ = nullptr;
  Out<std::int64_t> stamp_;
};

/// The staying task of the switch benchmark (the robot interface's place): counts the cycles
/// whose input is not the stamp of its own release, i.e. whose producer's cycle was lost.
class BenchStampCheck final : public Module {
 public:
  static constexpr const char* kName = "bench_stamp_check";
  static constexpr const char* kSummary = "benchmark: counts cycles that missed their producer's value";
  static constexpr const char* kDoc = "stale = cycles whose input stamp is not their own release (bench only).";
  static void declare(Declarations& d, const Params& /*p*/) {
    d.in_var<std::int64_t>("stamp", Dim::fixed(1), "stamp");
    d.out_var<std::int64_t>("stale", Dim::fixed(1), "cycles that read another release's stamp");
  }

 protected:
  Status init(InitContext& ctx) override {
    timing_ = &ctx.timing();
    stamp_ = ctx.in<std::int64_t>("stamp");
    stale_ = ctx.out<std::int64_t>("stale");
    return Status::ok();
  }
  Status cycle() override {
    if (stamp_[0] != timing_->release_ns) ++stale_[0];
    return Status::ok();
  }

 private:
  const CycleTiming* timing_ = nullptr;
  In<std::int64_t> stamp_;
  Out<std::int64_t> stale_;
};

}  // namespace chimera::bench
