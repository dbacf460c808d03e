#pragma once
// Test modules for the scheduling tests on the virtual clock: a tracer that records when each of
// its jobs started (on the subsystem's clock), an aperiodic copier woken by a variable's update,
// and an aperiodic reader of a descriptor given by the test.

#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "chimera/module/registry.hpp"
#include "support/probe_module.hpp"

namespace chimera::testing {

struct TraceEntry {
  std::string task;
  std::int64_t release_ns = 0;
  std::int64_t start_ns = 0;
  bool operator==(const TraceEntry&) const = default;
};

/// Every job start of every tracer, in the order they happened; cleared by the tests.
inline std::vector<TraceEntry>& trace() {
  static std::vector<TraceEntry> t;
  return t;
}

/// Records its job starts. Its time comes from the task's virtual_exec. Allocates in cycle():
/// tests only.
class Tracer : public Module {
 public:
  static constexpr const char* kName = "tracer";
  static constexpr const char* kSummary = "records job starts";
  static constexpr const char* kDoc = "appends (task, release, start) to testing::trace()";
  static void declare(Declarations& d, const Params&) { d.param("recover", false, "", "error() recovers"); }

 protected:
  Status init(InitContext& ctx) override {
    name_ = std::string(ctx.task_name());
    timing_ = &ctx.timing();
    recover_ = ctx.params().flag("recover");
    return Status::ok();
  }
  Status cycle() override {
    trace().push_back({name_, timing_->release_ns, timing_->start_ns});
    return Status::ok();
  }
  Status error() override { return recover_ ? Status::ok() : Status::fail("tracer does not recover"); }

 private:
  std::string name_;
  const CycleTiming* timing_ = nullptr;
  bool recover_ = false;
};

/// Aperiodic: one cycle per new value of in-var `count`, which it copies to `seen`; counts its
/// cycles in `served`.
class UpdateCopier : public Module {
 public:
  static constexpr const char* kName = "update_copier";
  static constexpr const char* kSummary = "copies count when it changes";
  static constexpr const char* kDoc = "aperiodic, triggered by updates of count";
  static void declare(Declarations& d, const Params&) {
    d.in_var<std::int64_t>("count", Dim::fixed(1), "input");
    d.out_var<std::int64_t>("seen", Dim::fixed(1), "the input, copied");
    d.out_var<std::int64_t>("served", Dim::fixed(1), "cycles run");
  }

 protected:
  Status init(InitContext& ctx) override {
    in_ = ctx.in<std::int64_t>("count");
    seen_ = ctx.out<std::int64_t>("seen");
    served_ = ctx.out<std::int64_t>("served");
    ctx.trigger_on_update("count");
    return Status::ok();
  }
  Status cycle() override {
    seen_[0] = in_[0];
    ++served_[0];
    return Status::ok();
  }

 private:
  In<std::int64_t> in_;
  Out<std::int64_t> seen_;
  Out<std::int64_t> served_;
};

/// Aperiodic: one cycle per byte readable on descriptor `fd` (a pipe the test fills); counts
/// the bytes in `bytes_read`.
class FdReader : public Module {
 public:
  static constexpr const char* kName = "fd_reader";
  static constexpr const char* kSummary = "reads one byte per event";
  static constexpr const char* kDoc = "aperiodic, triggered by a readable descriptor";
  static void declare(Declarations& d, const Params&) {
    d.out_var<std::int64_t>("bytes_read", Dim::fixed(1), "bytes read");
    d.param("fd", -1.0, "", "the descriptor to read");
  }

 protected:
  Status init(InitContext& ctx) override {
    fd_ = static_cast<int>(ctx.params().number("fd", -1));
    read_ = ctx.out<std::int64_t>("bytes_read");
    ctx.trigger_on_fd(fd_);
    return Status::ok();
  }
  Status sync() override {
    char byte = 0;
    got_ = ::read(fd_, &byte, 1) == 1;
    return Status::ok();
  }
  Status cycle() override {
    if (got_) ++read_[0];
    return Status::ok();
  }

 private:
  int fd_ = -1;
  bool got_ = false;
  Out<std::int64_t> read_;
};

/// Set by a test to let every Staller's stuck cycle return.
inline std::atomic<bool>& stall_released() {
  static std::atomic<bool> released{false};
  return released;
}

/// Its cycle number `stall_at` does not return until the test sets stall_released(): a job stuck
/// in cycle(), for the overrun watch. Counts its cycles in out-var `done`. Real clock only.
class Staller : public Module {
 public:
  static constexpr const char* kName = "staller";
  static constexpr const char* kSummary = "a cycle that does not return until released";
  static constexpr const char* kDoc = "cycle number stall_at waits for testing::stall_released()";
  static void declare(Declarations& d, const Params&) {
    d.out_var<std::int64_t>("done", Dim::fixed(1), "cycles run");
    d.param("stall_at", 3.0, "cycles", "the cycle that gets stuck");
    d.param("recover", false, "", "error() recovers");
  }

 protected:
  Status init(InitContext& ctx) override {
    stall_at_ = static_cast<std::int64_t>(ctx.params().number("stall_at"));
    recover_ = ctx.params().flag("recover");
    done_ = ctx.out<std::int64_t>("done");
    return Status::ok();
  }
  Status cycle() override {
    if (++cycles_ == stall_at_) {
      // Acquire: pairs with the test's release store; nothing else is shared.
      while (!stall_released().load(std::memory_order_acquire)) ::usleep(1000);
    }
    done_[0] = cycles_;
    return Status::ok();
  }
  Status error() override { return recover_ ? Status::ok() : Status::fail("staller does not recover"); }

 private:
  std::int64_t stall_at_ = 0;
  std::int64_t cycles_ = 0;
  bool recover_ = false;
  Out<std::int64_t> done_;
};

/// The probe registry's modules plus these, plus the library's cpu_load.
inline Registry& scheduling_registry() {
  static Registry r = [] {
    Registry reg;
    (void)reg.add(info_of<Probe>());
    (void)reg.add(info_of<Counter>());
    (void)reg.add(info_of<Follower>());
    (void)reg.add(info_of<Tracer>());
    (void)reg.add(info_of<UpdateCopier>());
    (void)reg.add(info_of<FdReader>());
    (void)reg.add(info_of<Staller>());
    for (const char* library_module : {"cpu_load", "udp_command"})
      if (const ModuleInfo* m = Registry::global().find(library_module)) (void)reg.add(*m);
    return reg;
  }();
  return r;
}

}  // namespace chimera::testing
