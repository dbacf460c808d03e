// joint_traj_gen: the joint position trajectory generator of the paper's Figure 4.

#include "module_docs/joint_traj_gen.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

#include "chimera/module/registry.hpp"
#include "quintic_via.hpp"

namespace chimera::modules {
namespace {

constexpr double kDefaultSegmentTime = 1.5;  // s
constexpr double kDefaultHoldTime = 0.3;     // s
constexpr bool kDefaultLoop = true;

// A motion that uses every joint of the shipped arm and stays well inside its limits.
Matrix default_via() {
  return {{0.8, 0.6, -0.5, 1.0, 0.8, 1.2}, {-0.8, 0.2, 0.4, -1.0, -0.6, -1.2}, {0.0, 0.9, -1.0, 0.0, 1.0, 0.0}};
}

class JointTrajGen final : public Module {
 public:
  static constexpr const char* kName = "joint_traj_gen";
  static constexpr const char* kSummary = docs::joint_traj_gen::kSummary;
  static constexpr const char* kDoc = docs::joint_traj_gen::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("theta_m", Dim::of("ndof"), "measured joint positions, rad (where the motion starts)");
    d.out_var("theta_d", Dim::of("ndof"), "desired joint positions, rad");
    d.out_var("dtheta_d", Dim::of("ndof"), "desired joint velocities, rad/s");
    d.param("via", default_via(), "rad", "via points, one joint vector (ndof entries) each");
    d.param("segment_time", kDefaultSegmentTime, "s", "duration of each move between via points").greater_than(0);
    d.param("hold_time", kDefaultHoldTime, "s", "rest at each via point").at_least(0);
    d.param("loop", kDefaultLoop, "", "after the last via point go on to the first, forever");
  }

 protected:
  Status init(InitContext& ctx) override {
    ndof_ = ctx.in<double>("ndof");
    theta_m_ = ctx.in<double>("theta_m");
    theta_d_ = ctx.out<double>("theta_d");
    dtheta_d_ = ctx.out<double>("dtheta_d");
    // An unbound view already fails init with a message naming the port (InitContext's rule).
    if (ctx.failed()) return Status::ok();
    if (!ndof_matches()) return Status::fail("joint_traj_gen: in-const ndof differs from the size of its ports");
    const std::size_t n = theta_d_.size();

    period_ns_ = ctx.timing().period_ns;
    if (period_ns_ <= 0) return Status::fail("joint_traj_gen: the task must be periodic (time is cycles x period)");
    const Params& p = ctx.params();
    const double segment_s = p.number("segment_time", kDefaultSegmentTime);
    const double hold_s = p.number("hold_time", kDefaultHoldTime);
    const auto segment_ns = static_cast<std::int64_t>(std::llround(segment_s * 1e9));
    const auto hold_ns = static_cast<std::int64_t>(std::llround(hold_s * 1e9));
    if (!(segment_s > 0.0) || segment_ns <= 0) return Status::fail("joint_traj_gen: segment_time must be > 0 s");
    if (!(hold_s >= 0.0)) return Status::fail("joint_traj_gen: hold_time must be >= 0 s");

    const Matrix via = p.matrix("via", default_via());
    if (via.empty()) return Status::fail("joint_traj_gen: via needs at least one point");
    std::vector<double> flat;
    flat.reserve(via.size() * n);
    for (const auto& point : via) {
      if (point.size() != n) return Status::fail("joint_traj_gen: every via point must have ndof entries");
      for (double v : point) {
        if (!std::isfinite(v)) return Status::fail("joint_traj_gen: via points must be finite numbers");
        flat.push_back(v);
      }
    }
    path_.configure(n, std::move(flat), segment_ns, hold_ns, p.flag("loop", kDefaultLoop));
    return Status::ok();
  }

  // A new producer of ndof took over: fine as long as the arm has as many joints as before.
  Status reinit() override {
    return ndof_matches() ? Status::ok() : Status::fail("joint_traj_gen: in-const ndof changed; respawn the task");
  }

  Status on() override {
    // Publish "stay where you are" at once, so that a controller turned on with us never sees
    // the zeros of a fresh table as a target.
    start_from_measured();
    path_.sample(0, theta_d_.values(), dtheta_d_.values());
    cycles_ = 0;
    started_ = false;
    return Status::ok();
  }

  Status cycle() override {
    // The first cycle takes theta_m again: it is at least as fresh as at on().
    if (!started_) {
      start_from_measured();
      started_ = true;
    }
    path_.sample(static_cast<std::int64_t>(cycles_) * period_ns_, theta_d_.values(), dtheta_d_.values());
    ++cycles_;
    return Status::ok();
  }

 private:
  // The resolver sized the ports from ndof before anything ran, so the sizes are the truth; the
  // value itself may not be in the table yet when tasks are spawned before its producer.
  [[nodiscard]] bool ndof_matches() const noexcept {
    if (!ndof_.has_data() || ndof_[0] == 0.0) return true;
    return ndof_[0] == static_cast<double>(theta_d_.size());
  }

  void start_from_measured() noexcept {
    path_.restart(theta_m_.has_data() ? theta_m_.values() : std::span<const double>());
  }

  In<double> ndof_;
  In<double> theta_m_;
  Out<double> theta_d_;
  Out<double> dtheta_d_;
  QuinticVia path_;
  std::int64_t period_ns_ = 0;
  std::uint64_t cycles_ = 0;  // cycles since on
  bool started_ = false;
};

CHIMERA_REGISTER_MODULE(JointTrajGen);

}  // namespace
}  // namespace chimera::modules
