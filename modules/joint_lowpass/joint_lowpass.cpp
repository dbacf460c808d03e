// joint_lowpass: a first-order low-pass filter per joint (the filter of Figure 4's filtered chain).

#include "module_docs/joint_lowpass.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <vector>

#include "chimera/module/fault_tolerance.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::modules {
namespace {

constexpr double kDefaultLateLimit = 100;
constexpr double kDefaultCutoffHz = 50.0;

class JointLowpass final : public Module {
 public:
  static constexpr const char* kName = "joint_lowpass";
  static constexpr const char* kSummary = docs::joint_lowpass::kSummary;
  static constexpr const char* kDoc = docs::joint_lowpass::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("u", Dim::of("ndof"), "input, one value per joint");
    d.out_var("y", Dim::of("ndof"), "filtered input");
    d.param("cutoff_hz", kDefaultCutoffHz, "Hz", "cut-off frequency (-3 dB) of the filter").greater_than(0);
    d.param("late_limit", kDefaultLateLimit, "cycles",
            "timing faults (late cycles, budget overruns) in a row that error() recovers from before ERROR").whole().at_least(1);
  }

 protected:
  Status init(InitContext& ctx) override {
    u_ = ctx.in<double>("u");
    y_ = ctx.out<double>("y");
    if (ctx.failed()) return Status::ok();  // an unbound view already fails init, naming the port
    const double dt = ctx.period_s();
    if (!(dt > 0.0)) return Status::fail("joint_lowpass: the task must be periodic (the filter uses the period)");
    const double fc = ctx.params().number("cutoff_hz", kDefaultCutoffHz);
    if (!(fc > 0.0) || !std::isfinite(fc)) return Status::fail("joint_lowpass: cutoff_hz must be a number > 0");
    // The exact discretisation of dy/dt = (u - y) / tau with u held over the period.
    alpha_ = 1.0 - std::exp(-2.0 * std::numbers::pi * fc * dt);
    state_.assign(y_.size(), 0.0);
    timing_ = &ctx.timing();
    tolerance_ = TimingFaultTolerance(
        static_cast<std::uint64_t>(std::max(1.0, ctx.params().number("late_limit", kDefaultLateLimit))));
    return Status::ok();
  }

  // A late cycle is only late: recover, unless the lateness goes on (late_limit in a row).
  Status error() override { return tolerance_.judge(*timing_); }

  Status on() override {
    primed_ = false;  // the first input after on is taken as is: no ramp up from zero
    return Status::ok();
  }

  Status cycle() override {
    if (!u_.has_data()) return Status::ok();  // nothing to filter yet: y stays unwritten
    for (std::size_t i = 0; i < state_.size(); ++i) {
      state_[i] = primed_ ? state_[i] + alpha_ * (u_[i] - state_[i]) : u_[i];
      y_[i] = state_[i];
    }
    primed_ = true;
    return Status::ok();
  }

 private:
  const CycleTiming* timing_ = nullptr;
  TimingFaultTolerance tolerance_{static_cast<std::uint64_t>(kDefaultLateLimit)};
  In<double> u_;
  Out<double> y_;
  std::vector<double> state_;  // the filter's state, one per joint (sized in init)
  double alpha_ = 1.0;
  bool primed_ = false;
};

CHIMERA_REGISTER_MODULE(JointLowpass);

}  // namespace
}  // namespace chimera::modules
