// torque_limit: clamps each joint's torque to +-limit (between a controller and the robot).

#include "module_docs/torque_limit.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "chimera/module/fault_tolerance.hpp"
#include "chimera/module/registry.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

constexpr double kDefaultLateLimit = 100;
Vector default_limit() { return {150, 150, 80, 20, 20, 20}; }

class TorqueLimit final : public Module {
 public:
  static constexpr const char* kName = "torque_limit";
  static constexpr const char* kSummary = docs::torque_limit::kSummary;
  static constexpr const char* kDoc = docs::torque_limit::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("tau_in", Dim::of("ndof"), "requested joint torques, N*m");
    d.out_var("tau_out", Dim::of("ndof"), "joint torques clamped to +-limit, N*m");
    d.param("limit", default_limit(), "N*m", "torque limit per joint (or one for all)").at_least(0);
    d.param("late_limit", kDefaultLateLimit, "cycles",
            "timing faults (late cycles, budget overruns) in a row that error() recovers from before ERROR")
        .whole()
        .at_least(1);
  }

 protected:
  Status init(InitContext& ctx) override {
    in_ = ctx.in<double>("tau_in");
    out_ = ctx.out<double>("tau_out");
    if (ctx.failed()) return Status::ok();  // an unbound view already fails init, naming the port
    limit_ = per_joint(ctx.params(), "limit", default_limit(), out_.size());
    if (limit_.empty() || !all_non_negative(limit_))
      return ctx.refuse("limit", "torque_limit: limit needs ndof (or 1) values, none negative");
    timing_ = &ctx.timing();
    tolerance_ = TimingFaultTolerance(
        static_cast<std::uint64_t>(std::max(1.0, ctx.params().number("late_limit", kDefaultLateLimit))));
    return Status::ok();
  }

  // A late cycle is only late: recover, unless the lateness goes on (late_limit in a row).
  Status error() override { return tolerance_.judge(*timing_); }

  Status on() override {
    zero_output();
    return Status::ok();
  }

  Status cycle() override {
    if (!in_.has_data()) {
      zero_output();  // no request yet: no torque
      return Status::ok();
    }
    for (std::size_t i = 0; i < out_.size(); ++i) out_[i] = std::clamp(in_[i], -limit_[i], limit_[i]);
    return Status::ok();
  }

  Status off() override {
    zero_output();
    return Status::ok();
  }

 private:
  const CycleTiming* timing_ = nullptr;
  TimingFaultTolerance tolerance_{static_cast<std::uint64_t>(kDefaultLateLimit)};
  void zero_output() noexcept {
    for (std::size_t i = 0; i < out_.size(); ++i) out_[i] = 0.0;
  }

  In<double> in_;
  Out<double> out_;
  Vector limit_;
};

CHIMERA_REGISTER_MODULE(TorqueLimit);

}  // namespace
}  // namespace chimera::modules
