// visual_servo: the simulated vision subsystem of the paper's Figures 8 and 9 (Nelson and Khosla's
// visual tracking): a camera that sees a moving target with noise and latency, and the desired
// tool pose x_d that servoes the tool onto it.

#include "module_docs/visual_servo.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <string_view>

#include "chimera/module/registry.hpp"
#include "chimera/sim/gaussian_noise.hpp"
#include "support/module_support.hpp"
#include "target_path.hpp"

namespace chimera::modules {
namespace {

// In front of the shipped arm, the tool tilted 45 degrees forward and down; the path sways it
// 8 cm to the sides, 4 cm up and down and 5 cm in and out, one cycle in 10 to 17 s, keeping the
// arm in well-conditioned postures (docs/modules/visual_servo.md).
Vector default_center() { return {0.82, 0.10, 0.78, 0.0, 2.356, 0.0}; }
Vector default_amplitude() { return {0.05, 0.08, 0.04, 0.0, 0.0, 0.0}; }
Vector default_frequency() { return {0.07, 0.1, 0.06, 0.0, 0.0, 0.0}; }
Vector default_phase() { return {0.0, 0.0, 1.5708, 0.0, 0.0, 0.0}; }
constexpr double kDefaultLatency = 0.05;            // s
constexpr double kDefaultPositionNoise = 0.001;     // m
constexpr double kDefaultOrientationNoise = 0.002;  // rad

class VisualServo final : public Module {
 public:
  static constexpr const char* kName = "visual_servo";
  static constexpr const char* kSummary = docs::visual_servo::kSummary;
  static constexpr const char* kDoc = docs::visual_servo::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_var("x_m", Dim::fixed(6), "measured tool pose [x y z rx ry rz]: m, and a rotation vector in rad");
    d.out_var("x_d", Dim::fixed(6), "desired tool pose, as x_m");
    d.param("gain", 1.0, "", "fraction of the way from x_m to the seen target that x_d asks for (0 to 1]")
        .greater_than(0)
        .at_most(1);
    d.param("latency", kDefaultLatency, "s", "age of the image a result comes from").at_least(0);
    d.param("position_noise", kDefaultPositionNoise, "m", "standard deviation of the error of each seen coordinate")
        .at_least(0);
    d.param("orientation_noise", kDefaultOrientationNoise, "rad",
            "standard deviation of the seen orientation's error about each axis")
        .at_least(0);
    d.param("seed", 1.0, "", "seed of the noise (runs repeat exactly)");
    d.param("center", default_center(), "m, rad", "the target's mean pose [x y z rx ry rz]");
    d.param("amplitude", default_amplitude(), "m, rad", "amplitude of each number's sine wave");
    d.param("frequency", default_frequency(), "Hz", "frequency of each number's sine wave (6 values, or 1 for all)");
    d.param("phase", default_phase(), "rad", "phase of each number's sine wave (6 values, or 1 for all)");
    d.resource("a simulated camera watching a target on a path of sine waves (modules/visual_servo/target_path.hpp)");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    timing_ = &ctx.timing();
    gain_ = p.number("gain", 1.0);
    latency_ = p.number("latency", kDefaultLatency);
    position_noise_ = p.number("position_noise", kDefaultPositionNoise);
    orientation_noise_ = p.number("orientation_noise", kDefaultOrientationNoise);
    if (!(gain_ > 0.0 && gain_ <= 1.0)) return Status::fail("visual_servo: gain must be in (0, 1]");
    if (!(latency_ >= 0.0) || !(position_noise_ >= 0.0) || !(orientation_noise_ >= 0.0))
      return Status::fail("visual_servo: latency, position_noise and orientation_noise must be >= 0");
    noise_.reseed(static_cast<std::uint64_t>(std::llround(std::fabs(p.number("seed", 1.0)))));

    TargetPathSettings path;
    const auto fill = [&](std::string_view name, Vector fallback, std::array<double, 6>& out) {
      const Vector v = per_joint(p, name, std::move(fallback), 6);
      if (v.size() != 6) return false;
      std::copy(v.begin(), v.end(), out.begin());
      return true;
    };
    if (!fill("center", default_center(), path.center) || !fill("amplitude", default_amplitude(), path.amplitude) ||
        !fill("frequency", default_frequency(), path.frequency) || !fill("phase", default_phase(), path.phase))
      return Status::fail("visual_servo: center, amplitude, frequency and phase need 6 (or 1) finite values");
    path_ = TargetPath(path);

    x_m_ = ctx.in<double>("x_m");
    x_d_ = ctx.out<double>("x_d");
    if (ctx.failed()) return Status::ok();  // InitContext names the port that did not bind
    publish_target();
    return Status::ok();
  }

  Status on() override {
    publish_target();
    return Status::ok();
  }

  // One image a cycle: the target where it was `latency` ago, as the camera sees it; x_d is the
  // tool pose a fraction gain of the way from where the tool is to there.
  Status cycle() override {
    const kinematics::Pose seen = see(now_s());
    if (!x_m_.has_data()) {
      kinematics::write_pose(seen, x_d_.values());
      return Status::ok();
    }
    const kinematics::Pose tool = kinematics::pose_from(x_m_.values());
    kinematics::write_pose(kinematics::step_toward(tool, seen, gain_), x_d_.values());
    return Status::ok();
  }

 private:
  [[nodiscard]] double now_s() const noexcept { return static_cast<double>(timing_->release_ns) * 1e-9; }

  // The target at t - latency (its start before the first image is ready), with the camera's
  // error: Gaussian in each coordinate, and a small rotation of Gaussian angles about each axis.
  kinematics::Pose see(double t) noexcept {
    kinematics::Pose pose = path_.at(std::max(t - latency_, 0.0));
    kinematics::Vector6 error;
    for (Eigen::Index i = 0; i < 3; ++i) error[i] = position_noise_ * noise_.next();
    for (Eigen::Index i = 3; i < 6; ++i) error[i] = orientation_noise_ * noise_.next();
    return kinematics::displace(pose, error);
  }

  // Before any cycle, the tool pose cannot be trusted (its producer may not have run): x_d is the
  // target as first seen, a pose the arm can go to.
  void publish_target() noexcept { kinematics::write_pose(see(now_s()), x_d_.values()); }

  const CycleTiming* timing_ = nullptr;
  TargetPath path_;
  sim::GaussianNoise noise_;
  double gain_ = 1.0;
  double latency_ = kDefaultLatency;
  double position_noise_ = kDefaultPositionNoise;
  double orientation_noise_ = kDefaultOrientationNoise;
  In<double> x_m_;
  Out<double> x_d_;
};

CHIMERA_REGISTER_MODULE(VisualServo);

}  // namespace
}  // namespace chimera::modules
