#pragma once
// Test modules for the lifecycle and the executive: a probe whose methods fail or throw on
// demand and which counts how often each was called, a counter producer and a copying consumer.

#include <unistd.h>

#include <array>
#include <atomic>
#include <map>
#include <stdexcept>
#include <string>

#include "chimera/module/registry.hpp"

namespace chimera::testing {

enum Method : std::size_t { kInit, kOn, kCycle, kOff, kKill, kError, kClear, kMethodCount };

/// Calls per method, per task name; reset by the tests.
inline std::map<std::string, std::array<int, kMethodCount>>& calls() {
  static std::map<std::string, std::array<int, kMethodCount>> c;
  return c;
}

/// The probe: params `fail` (a method name whose call fails), `throw` (fail by throwing),
/// `recover` (error() recovers), `clear_ok` (clear() reports the fault gone).
class Probe : public Module {
 public:
  static constexpr const char* kName = "probe";
  static constexpr const char* kSummary = "test probe";
  static constexpr const char* kDoc = "fails on demand";
  static void declare(Declarations& d, const Params&) {
    d.out_var<std::int64_t>("probe_count", Dim::fixed(1), "cycles run");
    d.param("fail", std::string("none"), "", "method that fails");
    d.param("throw", false, "", "fail by throwing");
    d.param("recover", false, "", "error() recovers");
    d.param("clear_ok", true, "", "clear() succeeds");
    d.param("fail_after", 0.0, "cycles", "cycle fails only after this many cycles");
  }

 protected:
  Status init(InitContext& ctx) override {
    name_ = std::string(ctx.task_name());
    fail_ = ctx.params().text("fail", "none");
    throw_ = ctx.params().flag("throw");
    recover_ = ctx.params().flag("recover");
    clear_ok_ = ctx.params().flag("clear_ok", true);
    fail_after_ = static_cast<int>(ctx.params().number("fail_after"));
    count_ = ctx.out<std::int64_t>("probe_count");
    return hit(kInit, "init");
  }
  Status on() override { return hit(kOn, "on"); }
  Status cycle() override {
    ++count_[0];
    if (count_[0] <= fail_after_) {
      ++calls()[name_][kCycle];
      return Status::ok();
    }
    return hit(kCycle, "cycle");
  }
  Status off() override { return hit(kOff, "off"); }
  Status kill() override { return hit(kKill, "kill"); }
  Status error() override {
    ++calls()[name_][kError];
    return recover_ ? Status::ok() : Status::fail("probe does not recover");
  }
  Status clear() override {
    ++calls()[name_][kClear];
    return clear_ok_ ? Status::ok() : Status::fail("probe still broken");
  }

 private:
  Status hit(Method m, const char* name) {
    ++calls()[name_][m];
    if (fail_ != name) return Status::ok();
    if (throw_) throw std::runtime_error(std::string("probe threw in ") + name);
    return Status::fail("probe failed on purpose");
  }

  std::string name_;
  std::string fail_;
  bool throw_ = false;
  bool recover_ = false;
  bool clear_ok_ = true;
  int fail_after_ = 0;
  Out<std::int64_t> count_;
};

/// Produces `count`: its cycle number (1, 2, ...).
class Counter : public Module {
 public:
  static constexpr const char* kName = "counter";
  static constexpr const char* kSummary = "counts cycles";
  static constexpr const char* kDoc = "out-var count = number of cycles run";
  static void declare(Declarations& d, const Params&) { d.out_var<std::int64_t>("count", Dim::fixed(1), "cycles"); }

 protected:
  Status init(InitContext& ctx) override {
    count_ = ctx.out<std::int64_t>("count");
    return Status::ok();
  }
  Status cycle() override {
    ++count_[0];
    return Status::ok();
  }

 private:
  Out<std::int64_t> count_;
};

/// Copies in-var `count` to out-var `copy` and counts the cycles that read a value older than
/// the producer's cycle of the same release: a counter started together with it has written
/// its n-th value at the release of our n-th cycle, so reading less than our cycle number means
/// we ran before it, a cycle of lag. (Reading more is fine: we are late and catching up.)
class Follower : public Module {
 public:
  static constexpr const char* kName = "follower";
  static constexpr const char* kSummary = "copies count";
  static constexpr const char* kDoc = "copy = count";
  static void declare(Declarations& d, const Params&) {
    d.in_var<std::int64_t>("count", Dim::fixed(1), "input");
    d.out_var<std::int64_t>("copy", Dim::fixed(1), "the input, copied");
    d.out_var<std::int64_t>("lagged", Dim::fixed(1), "cycles that read a stale input");
    d.out_var<std::int64_t>("follower_cycles", Dim::fixed(1), "cycles run");
  }

 protected:
  Status init(InitContext& ctx) override {
    in_ = ctx.in<std::int64_t>("count");
    copy_ = ctx.out<std::int64_t>("copy");
    lagged_ = ctx.out<std::int64_t>("lagged");
    cycles_ = ctx.out<std::int64_t>("follower_cycles");
    return Status::ok();
  }
  Status cycle() override {
    copy_[0] = in_[0];
    ++cycles_[0];
    if (in_[0] < cycles_[0]) ++lagged_[0];
    return Status::ok();
  }

 private:
  In<std::int64_t> in_;
  Out<std::int64_t> copy_;
  Out<std::int64_t> lagged_;
  Out<std::int64_t> cycles_;
};

template <class M>
ModuleInfo info_of() {
  return ModuleInfo{M::kName, M::kSummary, M::kDoc, [](Declarations& d, const Params& p) { M::declare(d, p); },
                    []() -> std::unique_ptr<Module> { return std::make_unique<M>(); }};
}

/// A registry holding the three test modules.
inline Registry& test_registry() {
  static Registry r = [] {
    Registry reg;
    (void)reg.add(info_of<Probe>());
    (void)reg.add(info_of<Counter>());
    (void)reg.add(info_of<Follower>());
    return reg;
  }();
  return r;
}

/// A name for shared memory that no other test process uses.
inline std::string unique_suffix() {
  static std::atomic<int> n{0};
  return "_t" + std::to_string(::getpid()) + "_" + std::to_string(n.fetch_add(1));
}

}  // namespace chimera::testing
