// singularity_monitor: watches the arm's manipulability and asks the subsystem to switch to its
// near-singularity configuration when it falls, and back when it has recovered (paper 3.4: "when
// the robot is at risk of going through a singularity, a signal is sent to the subsystem
// interface indicating that a dynamic reconfiguration ... is required").

#include "module_docs/singularity_monitor.hpp"

#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "chimera/module/registry.hpp"

namespace chimera::modules {
namespace {

class SingularityMonitor final : public Module {
 public:
  static constexpr const char* kName = "singularity_monitor";
  static constexpr const char* kSummary = docs::singularity_monitor::kSummary;
  static constexpr const char* kDoc = docs::singularity_monitor::kText;

  static void declare(Declarations& d, const Params& /*params*/) {
    d.in_const("ndof", Dim::fixed(1), "degrees of freedom");
    d.in_var("jacobian", Dim::of("ndof", 6), "geometric Jacobian, 6 x ndof row-major");
    d.out_var("manipulability", Dim::fixed(1), "w = sqrt(det(J J^T))");
    d.param("enter", 0.06, "", "below this manipulability it asks for `near`").greater_than(0);
    d.param("leave", 0.075, "", "above this manipulability it asks for `safe`");
    d.param("near", std::string("near_singularity"), "", "configuration to ask for near a singular posture");
    d.param("safe", std::string("standard"), "", "configuration to ask for once away from it");
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    enter_ = p.number("enter", 0.06);
    leave_ = p.number("leave", 0.075);
    if (!(enter_ > 0.0) || !(leave_ > enter_))
      return Status::fail(
          "singularity_monitor: needs 0 < enter < leave (the band between them keeps it from chattering)");
    jacobian_ = ctx.in<double>("jacobian");
    w_ = ctx.out<double>("manipulability");
    to_near_ = ctx.switch_request(p.text("near", "near_singularity"));
    to_safe_ = ctx.switch_request(p.text("safe", "standard"));
    if (ctx.failed()) return Status::ok();  // InitContext names what did not bind
    if (jacobian_.size() % 6 != 0 || jacobian_.size() == 0)
      return Status::fail("singularity_monitor: the jacobian must be 6 x ndof");
    return Status::ok();
  }

  Status cycle() override {
    if (!jacobian_.has_data()) return Status::ok();
    const auto n = static_cast<Eigen::Index>(jacobian_.size() / 6);
    const Eigen::Map<const Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>> j(jacobian_.values().data(), 6,
                                                                                        n);
    Eigen::Matrix<double, 6, 6> jjt;
    jjt.noalias() = j.lazyProduct(j.transpose());  // coefficient by coefficient: no allocation
    const double w = std::sqrt(std::max(jjt.determinant(), 0.0));
    w_[0] = w;
    // Asking again while a request is pending or done costs one exchange: ask every cycle the
    // condition holds, and the subsystem interface acts once.
    if (w < enter_) to_near_.ask();
    if (w > leave_) to_safe_.ask();
    return Status::ok();
  }

 private:
  In<double> jacobian_;
  Out<double> w_;
  SwitchRequest to_near_;
  SwitchRequest to_safe_;
  double enter_ = 0.06;
  double leave_ = 0.075;
};

CHIMERA_REGISTER_MODULE(SingularityMonitor);

}  // namespace
}  // namespace chimera::modules
