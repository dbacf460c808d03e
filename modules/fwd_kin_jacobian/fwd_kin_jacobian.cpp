// fwd_kin_jacobian: forward kinematics and Jacobian (paper, Figures 6, 8 and 9): the tool's pose
// x_m and the 6 x ndof geometric Jacobian from the measured joint positions, through an Orocos
// KDL chain read from the arm's URDF.

#include "module_docs/fwd_kin_jacobian.hpp"

#include <memory>
#include <string>

#include "chimera/module/registry.hpp"
#include "kinematics/arm_chain.hpp"
#include "support/chain_params.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

using kinematics::ArmChain;

class FwdKinJacobian final : public Module {
 public:
  static constexpr const char* kName = "fwd_kin_jacobian";
  static constexpr const char* kSummary = docs::fwd_kin_jacobian::kSummary;
  static constexpr const char* kDoc = docs::fwd_kin_jacobian::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("theta_m", Dim::of("ndof"), "measured joint positions, rad");
    d.out_var("x_m", Dim::fixed(6), "measured tool pose [x y z rx ry rz]: m, and a rotation vector in rad");
    d.out_var("jacobian", Dim::of("ndof", 6), "geometric Jacobian, 6 x ndof row-major, rows vx vy vz wx wy wz");
    declare_chain_params(d);
  }

 protected:
  Status init(InitContext& ctx) override {
    auto chain = load_chain(ctx.params());
    if (!chain) return ctx.refuse("urdf", intern("fwd_kin_jacobian: " + chain.error().message));
    chain_ = std::move(chain).value();
    theta_m_ = ctx.in<double>("theta_m");
    x_m_ = ctx.out<double>("x_m");
    jacobian_out_ = ctx.out<double>("jacobian");
    if (ctx.failed()) return Status::ok();  // InitContext names the port that did not bind
    if (theta_m_.size() != static_cast<std::size_t>(chain_->ndof()))
      return Status::fail(intern("fwd_kin_jacobian: the chain in '" + chain_->path() + "' has " +
                                 std::to_string(chain_->ndof()) + " joints, but ndof is " +
                                 std::to_string(theta_m_.size())));
    jacobian_ = kinematics::JacobianMatrix::Zero(6, chain_->ndof());
    compute();
    return Status::ok();
  }

  Status on() override {
    compute();
    return Status::ok();
  }

  Status cycle() override {
    compute();
    return Status::ok();
  }

  Status kill() override {
    chain_.reset();
    return Status::ok();
  }

 private:
  // Nothing to compute before some task has measured the joints.
  void compute() noexcept {
    if (!theta_m_.has_data()) return;
    kinematics::Pose pose;
    chain_->evaluate(theta_m_.values(), pose, jacobian_);
    kinematics::write_pose(pose, x_m_.values());
    const auto n = static_cast<std::size_t>(jacobian_.cols());
    for (std::size_t r = 0; r < 6; ++r)
      for (std::size_t c = 0; c < n; ++c)
        jacobian_out_[r * n + c] = jacobian_(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
  }

  std::unique_ptr<ArmChain> chain_;
  kinematics::JacobianMatrix jacobian_;
  In<double> theta_m_;
  Out<double> x_m_;
  Out<double> jacobian_out_;
};

CHIMERA_REGISTER_MODULE(FwdKinJacobian);

}  // namespace
}  // namespace chimera::modules
