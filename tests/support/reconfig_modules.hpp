#pragma once
// Test modules for dynamic reconfiguration: a producer that stamps each output with its release,
// a consumer that checks it reads the stamp of its own release, const producers and a consumer
// that counts its reinit() calls, a watcher of the illegal-configuration flag, and a task that
// asks for a switch.

#include <cstdint>
#include <string>

#include "chimera/module/registry.hpp"
#include "support/trace_module.hpp"

namespace chimera::testing {

/// Out-var `stamp` = the release of its cycle (ns); `stamps` counts them.
class Stamper : public Module {
 public:
  static constexpr const char* kName = "stamper";
  static constexpr const char* kSummary = "stamps its releases";
  static constexpr const char* kDoc = "stamp = release of the cycle";
  static void declare(Declarations& d, const Params&) {
    d.out_var<std::int64_t>("stamp", Dim::fixed(1), "release of the cycle that wrote it, ns");
  }

 protected:
  Status init(InitContext& ctx) override {
    stamp_ = ctx.out<std::int64_t>("stamp");
    timing_ = &ctx.timing();
    return Status::ok();
  }
  Status cycle() override {
    stamp_[0] = timing_->release_ns;
    return Status::ok();
  }

 private:
  Out<std::int64_t> stamp_;
  const CycleTiming* timing_ = nullptr;
};

/// Reads in-var `stamp` and counts in `stale` the cycles where it is not the stamp of its own
/// release (its producer, of the same period, did not run that release first); `checked` counts
/// its cycles.
class StampChecker : public Module {
 public:
  static constexpr const char* kName = "stamp_checker";
  static constexpr const char* kSummary = "checks stamps";
  static constexpr const char* kDoc = "stale = cycles that read another release's stamp";
  static void declare(Declarations& d, const Params&) {
    d.in_var<std::int64_t>("stamp", Dim::fixed(1), "stamp");
    d.out_var<std::int64_t>("stale", Dim::fixed(1), "cycles that read another release's stamp");
    d.out_var<std::int64_t>("checked", Dim::fixed(1), "cycles run");
  }

 protected:
  Status init(InitContext& ctx) override {
    stamp_ = ctx.in<std::int64_t>("stamp");
    stale_ = ctx.out<std::int64_t>("stale");
    checked_ = ctx.out<std::int64_t>("checked");
    timing_ = &ctx.timing();
    return Status::ok();
  }
  Status cycle() override {
    if (stamp_[0] != timing_->release_ns) ++stale_[0];
    ++checked_[0];
    return Status::ok();
  }

 private:
  In<std::int64_t> stamp_;
  Out<std::int64_t> stale_;
  Out<std::int64_t> checked_;
  const CycleTiming* timing_ = nullptr;
};

/// Publishes out-const `tool` = param `value` (a tool on the arm's flange, say).
class ToolConst : public Module {
 public:
  static constexpr const char* kName = "tool_const";
  static constexpr const char* kSummary = "publishes a constant";
  static constexpr const char* kDoc = "out-const tool = value";
  static void declare(Declarations& d, const Params& p) {
    d.out_const("tool", {p.number("value", 0.1)}, "tool length, m");
    d.param("value", 0.1, "m", "the constant");
  }
};

/// In-const `tool`; out-vars `reinits` (its reinit() calls) and `tool_seen` (the value in its
/// last cycle).
class ToolUser : public Module {
 public:
  static constexpr const char* kName = "tool_user";
  static constexpr const char* kSummary = "uses a constant";
  static constexpr const char* kDoc = "counts reinit() calls";
  static void declare(Declarations& d, const Params&) {
    d.in_const("tool", Dim::fixed(1), "tool length, m");
    d.out_var("reinits", Dim::fixed(1), "reinit() calls");
    d.out_var("tool_seen", Dim::fixed(1), "the tool length its last cycle used");
  }

 protected:
  Status init(InitContext& ctx) override {
    tool_ = ctx.in<double>("tool");
    reinits_ = ctx.out<double>("reinits");
    seen_ = ctx.out<double>("tool_seen");
    return Status::ok();
  }
  Status reinit() override {
    reinits_[0] += 1;
    return Status::ok();
  }
  Status cycle() override {
    seen_[0] = tool_[0];
    return Status::ok();
  }

 private:
  In<double> tool_;
  Out<double> reinits_;
  Out<double> seen_;
};

/// Counts in `flag_cycles` its cycles during which the illegal-configuration flag was up.
class FlagWatch : public Module {
 public:
  static constexpr const char* kName = "flag_watch";
  static constexpr const char* kSummary = "watches the flag";
  static constexpr const char* kDoc = "flag_cycles = cycles with the flag up";
  static void declare(Declarations& d, const Params&) {
    d.out_var<std::int64_t>("flag_cycles", Dim::fixed(1), "cycles with the flag up");
    d.out_var<std::int64_t>("watch_cycles", Dim::fixed(1), "cycles");
  }

 protected:
  Status init(InitContext& ctx) override {
    flags_ = &ctx.flags();
    up_ = ctx.out<std::int64_t>("flag_cycles");
    all_ = ctx.out<std::int64_t>("watch_cycles");
    return Status::ok();
  }
  Status cycle() override {
    if (flags_->illegal_configuration()) ++up_[0];
    ++all_[0];
    return Status::ok();
  }

 private:
  const SubsystemFlags* flags_ = nullptr;
  Out<std::int64_t> up_;
  Out<std::int64_t> all_;
};

/// Asks for a switch to configuration `target` at its cycle number `at` and every cycle after.
class Asker : public Module {
 public:
  static constexpr const char* kName = "asker";
  static constexpr const char* kSummary = "asks for a switch";
  static constexpr const char* kDoc = "asks for target from cycle `at` on";
  static void declare(Declarations& d, const Params&) {
    d.param("target", std::string(), "", "configuration to ask for");
    d.param("at", 1.0, "cycles", "first cycle that asks");
  }

 protected:
  Status init(InitContext& ctx) override {
    request_ = ctx.switch_request(ctx.params().text("target"));
    at_ = static_cast<std::uint64_t>(ctx.params().number("at", 1));
    return Status::ok();
  }
  Status cycle() override {
    if (++cycles_ >= at_) request_.ask();
    return Status::ok();
  }

 private:
  SwitchRequest request_;
  std::uint64_t at_ = 1;
  std::uint64_t cycles_ = 0;
};

/// The scheduling registry's modules plus these.
inline Registry& reconfig_registry() {
  static Registry r = [] {
    Registry reg;
    for (const ModuleInfo* m : scheduling_registry().list()) (void)reg.add(*m);
    (void)reg.add(info_of<Stamper>());
    (void)reg.add(info_of<StampChecker>());
    (void)reg.add(info_of<ToolConst>());
    (void)reg.add(info_of<ToolUser>());
    (void)reg.add(info_of<FlagWatch>());
    (void)reg.add(info_of<Asker>());
    return reg;
  }();
  return r;
}

}  // namespace chimera::testing
