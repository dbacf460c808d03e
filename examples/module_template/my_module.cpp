// my_module: y = k u, channel by channel. A port-based object (the paper's section 3.3) in a
// library of its own: declare the ports and parameters, override the methods you need, register.

#include <chimera/module/registry.hpp>

namespace {

class MyModule final : public chimera::Module {
 public:
  static constexpr const char* kName = "my_module";
  static constexpr const char* kSummary = "y = k u, channel by channel";
  static constexpr const char* kDoc =
      "Multiplies each of the ndof channels of the input u by the gain k (parameter, default 2) and "
      "publishes the result as y. Until a task has written u, y stays at zero.";

  // Ports may depend on the parameters; the framework allocates them and binds them to state
  // variables (renamed in the subsystem file with rename:).
  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.in_const("ndof", chimera::Dim::fixed(1), "number of channels");
    d.in_var("u", chimera::Dim::of("ndof"), "input");
    d.out_var("y", chimera::Dim::of("ndof"), "output, k u");
    // What a parameter accepts (at_least, greater_than, at_most, less_than, whole, one_of):
    // `chimera verify` refuses anything else with the file's line, before init could.
    d.param("k", 2.0, "", "gain").at_least(-100).at_most(100);
  }

 protected:
  // init may allocate and fail; the views it keeps are all that cycle touches.
  chimera::Status init(chimera::InitContext& ctx) override {
    u_ = ctx.in<double>("u");
    y_ = ctx.out<double>("y");
    k_ = ctx.params().number("k", 2.0);
    return chimera::Status::ok();
  }

  chimera::Status on() override {
    for (double& y : y_.values()) y = 0.0;
    return chimera::Status::ok();
  }

  // No error() here: the default does not recover. A hard task (the default criticality) made
  // from this module goes to ERROR at its first missed deadline, and `chimera run` exits 1. If a
  // late cycle is only late, say criticality: soft in the subsystem file, or recover here with
  // TimingFaultTolerance (chimera/module/fault_tolerance.hpp); docs/writing-modules.md, "What
  // happens at a missed deadline", says how to choose.

  // Real-time: no allocation, no exception, no lock, no formatting.
  chimera::Status cycle() override {
    if (!u_.has_data()) return chimera::Status::ok();
    for (std::size_t i = 0; i < y_.size(); ++i) y_[i] = k_ * u_[i];
    return chimera::Status::ok();
  }

 private:
  chimera::In<double> u_;
  chimera::Out<double> y_;
  double k_ = 2.0;
};

}  // namespace

CHIMERA_REGISTER_MODULE(MyModule);
