// inv_kin: inverse kinematics (paper, Figure 8): the joint positions that put the tool at the
// desired pose x_d, found numerically within the joint limits, continuing from the last solution.

#include "module_docs/inv_kin.hpp"

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "chimera/module/registry.hpp"
#include "kinematics/ik_solver.hpp"
#include "support/chain_params.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

constexpr double kDefaultIterations = 20;
constexpr double kDefaultTolerance = 1e-9;

class InvKin final : public Module {
 public:
  static constexpr const char* kName = "inv_kin";
  static constexpr const char* kSummary = docs::inv_kin::kSummary;
  static constexpr const char* kDoc = docs::inv_kin::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("x_d", Dim::fixed(6), "desired tool pose [x y z rx ry rz]: m, and a rotation vector in rad");
    d.in_var("theta_m", Dim::of("ndof"), "measured joint positions, rad (where the solution starts)");
    d.out_var("theta_d", Dim::of("ndof"), "desired joint positions, rad, within the joint limits");
    declare_chain_params(d);
    d.param("max_iterations", kDefaultIterations, "", "Levenberg-Marquardt iterations per cycle at most")
        .whole()
        .at_least(1)
        .at_most(10000);
    d.param("tolerance", kDefaultTolerance, "m, rad", "position and orientation error at which a solution is done")
        .greater_than(0);
    d.param("lower", Vector{}, "rad", "lower joint limits (one per joint, or one for all); empty: the URDF's");
    d.param("upper", Vector{}, "rad", "upper joint limits; empty: the URDF's");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    auto chain = load_chain(p);
    if (!chain) return ctx.refuse("urdf", intern("inv_kin: " + chain.error().message));
    chain_ = std::move(chain).value();
    const auto n = static_cast<std::size_t>(chain_->ndof());

    kinematics::IkSettings settings;
    const double iterations = p.number("max_iterations", kDefaultIterations);
    settings.position_tolerance = p.number("tolerance", kDefaultTolerance);
    settings.orientation_tolerance = settings.position_tolerance;
    if (!(iterations >= 1.0 && iterations <= 10'000.0) || !(settings.position_tolerance > 0.0))
      return Status::fail("inv_kin: max_iterations must be from 1 to 10000 and tolerance > 0");
    settings.max_iterations = static_cast<int>(iterations);
    const std::vector<double> urdf_lower(chain_->lower().begin(), chain_->lower().end());
    const std::vector<double> urdf_upper(chain_->upper().begin(), chain_->upper().end());
    Vector lower = per_joint(p, "lower", urdf_lower, n);
    Vector upper = per_joint(p, "upper", urdf_upper, n);
    if (p.vector("lower").empty()) lower = urdf_lower;  // the URDF's, infinite for a continuous joint
    if (p.vector("upper").empty()) upper = urdf_upper;
    if (lower.size() != n || upper.size() != n)
      return ctx.refuse(lower.size() != n ? "lower" : "upper",
                        "inv_kin: lower and upper need ndof (or 1) finite values");
    for (std::size_t i = 0; i < n; ++i)
      if (!(lower[i] <= upper[i])) return ctx.refuse("lower", "inv_kin: a lower joint limit is above its upper one");
    solver_.emplace(*chain_, std::move(lower), std::move(upper), settings);

    x_d_ = ctx.in<double>("x_d");
    theta_m_ = ctx.in<double>("theta_m");
    theta_d_ = ctx.out<double>("theta_d");
    if (ctx.failed()) return Status::ok();  // InitContext names the port that did not bind
    if (theta_d_.size() != n)
      return Status::fail(intern("inv_kin: the chain in '" + chain_->path() + "' has " + std::to_string(n) +
                                 " joints, but ndof is " + std::to_string(theta_d_.size())));
    solution_.assign(n, 0.0);
    start_from_measurement();
    return Status::ok();
  }

  Status on() override {
    start_from_measurement();
    return Status::ok();
  }

  // Each cycle continues from the last solution, so theta_d moves continuously along one branch
  // of the inverse; a pose not reached within max_iterations is approached further next cycle.
  Status cycle() override {
    if (x_d_.has_data()) (void)solver_->solve(kinematics::pose_from(x_d_.values()), solution_, solution_);
    std::copy(solution_.begin(), solution_.end(), theta_d_.values().begin());
    return Status::ok();
  }

  Status kill() override {
    solver_.reset();
    chain_.reset();
    return Status::ok();
  }

 private:
  // Where the arm is (within the limits) is the first solution: turned on, the task holds the arm.
  void start_from_measurement() noexcept {
    if (theta_m_.has_data()) {
      const auto lower = solver_->lower();
      const auto upper = solver_->upper();
      for (std::size_t i = 0; i < solution_.size(); ++i) solution_[i] = std::clamp(theta_m_[i], lower[i], upper[i]);
    }
    std::copy(solution_.begin(), solution_.end(), theta_d_.values().begin());
  }

  std::unique_ptr<kinematics::ArmChain> chain_;
  std::optional<kinematics::IkSolver> solver_;
  std::vector<double> solution_;  // sized in init
  In<double> x_d_;
  In<double> theta_m_;
  Out<double> theta_d_;
};

CHIMERA_REGISTER_MODULE(InvKin);

}  // namespace
}  // namespace chimera::modules
