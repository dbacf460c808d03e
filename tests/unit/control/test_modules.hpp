#pragma once
// Three tiny modules for the control tests, registered in a private Registry so that the
// process-wide one stays as the library made it.

#include <atomic>

#include "chimera/module/module.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::test {

/// Counts its cycles into `count`.
class Counter final : public Module {
 public:
  static constexpr const char* kName = "test_counter";
  static constexpr const char* kSummary = "counts its cycles";
  static constexpr const char* kDoc = "count = number of cycles since on";
  static void declare(Declarations& d, const Params& /*params*/) {
    d.out_var("count", Dim::fixed(1), "cycles since on");
  }

 protected:
  Status init(InitContext& ctx) override {
    count_ = ctx.out<double>("count");
    return Status::ok();
  }
  Status on() override {
    n_ = 0;
    return Status::ok();
  }
  Status cycle() override {
    count_[0] = static_cast<double>(++n_);
    return Status::ok();
  }

 private:
  Out<double> count_;
  long n_ = 0;
};

/// Doubles `count` into `doubled`.
class Doubler final : public Module {
 public:
  static constexpr const char* kName = "test_doubler";
  static constexpr const char* kSummary = "doubles its input";
  static constexpr const char* kDoc = "doubled = 2 count";
  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_var("count", Dim::fixed(1), "a number");
    d.out_var("doubled", Dim::fixed(1), "twice the number");
  }

 protected:
  Status init(InitContext& ctx) override {
    count_ = ctx.in<double>("count");
    doubled_ = ctx.out<double>("doubled");
    return Status::ok();
  }
  Status cycle() override {
    doubled_[0] = 2.0 * count_[0];
    return Status::ok();
  }

 private:
  In<double> count_;
  Out<double> doubled_;
};

/// Fails its cycle (and refuses clear) while `fail` is set; has no error handler, so a failure
/// leaves it in ERROR until an operator's clear.
class Faulty final : public Module {
 public:
  static constexpr const char* kName = "test_faulty";
  static constexpr const char* kSummary = "fails on demand";
  static constexpr const char* kDoc = "cycle() fails while the test says so";
  static void declare(Declarations& d, const Params& /*params*/) {
    d.out_var("health", Dim::fixed(1), "1 while healthy");
  }

  // NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): the test flips it
  static inline std::atomic<bool> fail{false};

 protected:
  Status init(InitContext& ctx) override {
    health_ = ctx.out<double>("health");
    return Status::ok();
  }
  Status cycle() override {
    // relaxed: a test flag, set between run_for calls on the same thread
    if (fail.load(std::memory_order_relaxed)) return Status::fail("asked to fail");
    health_[0] = 1.0;
    return Status::ok();
  }
  Status clear() override {
    return fail.load(std::memory_order_relaxed) ? Status::fail("still failing") : Status::ok();
  }

 private:
  Out<double> health_;
};

template <class M>
void add_module(Registry& registry) {
  auto added = registry.add(ModuleInfo{M::kName, M::kSummary, M::kDoc,
                                       [](Declarations& d, const Params& p) { M::declare(d, p); },
                                       []() -> std::unique_ptr<Module> { return std::make_unique<M>(); }});
  (void)added;
}

inline Registry& test_registry() {
  static Registry registry = [] {
    Registry r;
    add_module<Counter>(r);
    add_module<Doubler>(r);
    add_module<Faulty>(r);
    return r;
  }();
  return registry;
}

}  // namespace chimera::test
