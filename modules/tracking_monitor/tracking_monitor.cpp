// tracking_monitor: watches how well measured joint positions follow the desired ones.

#include "module_docs/tracking_monitor.hpp"

#include <algorithm>
#include <cmath>

#include "chimera/module/registry.hpp"

namespace chimera::modules {
namespace {

class TrackingMonitor final : public Module {
 public:
  static constexpr const char* kName = "tracking_monitor";
  static constexpr const char* kSummary = docs::tracking_monitor::kSummary;
  static constexpr const char* kDoc = docs::tracking_monitor::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("theta_d", Dim::of("ndof"), "desired joint positions, rad");
    d.in_var("theta_m", Dim::of("ndof"), "measured joint positions, rad");
    d.out_var("tracking_error", Dim::fixed(3), "[max |e| now, RMS since on, worst max |e| since on], rad");
    d.param("settle_time", 0.5, "s", "time after on that the RMS and the worst value ignore").at_least(0);
  }

 protected:
  Status init(InitContext& ctx) override {
    theta_d_ = ctx.in<double>("theta_d");
    theta_m_ = ctx.in<double>("theta_m");
    error_ = ctx.out<double>("tracking_error");
    settle_ns_ = static_cast<std::int64_t>(ctx.params().number("settle_time", 0.5) * 1e9);
    if (settle_ns_ < 0) return Status::fail("settle_time must not be negative");
    timing_ = &ctx.timing();
    return Status::ok();
  }

  Status on() override {
    on_ns_ = timing_->release_ns;
    sum_squares_ = 0.0;
    samples_ = 0;
    error_[0] = error_[1] = error_[2] = 0.0;
    return Status::ok();
  }

  Status cycle() override {
    if (!theta_d_.has_data() || !theta_m_.has_data()) return Status::ok();
    double worst_now = 0.0;
    double squares = 0.0;
    for (std::size_t i = 0; i < theta_d_.size(); ++i) {
      const double e = theta_d_[i] - theta_m_[i];
      worst_now = std::max(worst_now, std::abs(e));
      squares += e * e;
    }
    error_[0] = worst_now;
    if (timing_->release_ns - on_ns_ >= settle_ns_) {
      sum_squares_ += squares;
      samples_ += theta_d_.size();
      error_[1] = std::sqrt(sum_squares_ / static_cast<double>(samples_));
      error_[2] = std::max(error_[2], worst_now);
    }
    return Status::ok();
  }

 private:
  In<double> theta_d_;
  In<double> theta_m_;
  Out<double> error_;
  const CycleTiming* timing_ = nullptr;
  std::int64_t settle_ns_ = 0;
  std::int64_t on_ns_ = 0;
  double sum_squares_ = 0.0;
  std::size_t samples_ = 0;
};

}  // namespace

CHIMERA_REGISTER_MODULE(TrackingMonitor);

}  // namespace chimera::modules
