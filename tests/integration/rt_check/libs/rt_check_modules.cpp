// Two modules for `chimera run --rt-check`: one whose cycle() allocates as the author's
// did (a push_back every cycle, into a vector that never stops growing), and one that keeps to
// the real-time rules and must show no violation in the same run.

#include <vector>

#include <chimera/module/registry.hpp>

namespace {

class Hoarder final : public chimera::Module {
 public:
  static constexpr const char* kName = "test_hoarder";
  static constexpr const char* kSummary = "keeps every input in a growing vector (allocates in cycle)";
  static constexpr const char* kDoc = "Appends u to a history every cycle: a cycle that allocates.";

  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.in_var("u", chimera::Dim::fixed(1), "input");
  }

 protected:
  chimera::Status init(chimera::InitContext& ctx) override {
    u_ = ctx.in<double>("u");
    return chimera::Status::ok();
  }

  chimera::Status cycle() override {
    // A fresh vector each cycle, so that every cycle allocates (a growing one allocates only on
    // growth); the history is what a careless author keeps, and it allocates too.
    std::vector<double> sample;
    sample.push_back(u_.has_data() ? u_[0] : 0.0);
    history_.push_back(sample.front());
    return chimera::Status::ok();
  }

 private:
  chimera::In<double> u_;
  std::vector<double> history_;
};

class Counter final : public chimera::Module {
 public:
  static constexpr const char* kName = "test_quiet_counter";
  static constexpr const char* kSummary = "counts its cycles into y (allocates nothing in cycle)";
  static constexpr const char* kDoc = "Writes its cycle count to y; its buffer is reserved in init.";

  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.out_var("y", chimera::Dim::fixed(1), "cycles so far");
  }

 protected:
  chimera::Status init(chimera::InitContext& ctx) override {
    y_ = ctx.out<double>("y");
    scratch_.reserve(16);  // init may allocate: this must not be counted
    return chimera::Status::ok();
  }

  chimera::Status cycle() override {
    y_[0] += 1.0;
    return chimera::Status::ok();
  }

 private:
  chimera::Out<double> y_;
  std::vector<double> scratch_;
};

}  // namespace

CHIMERA_REGISTER_MODULE(Hoarder);
CHIMERA_REGISTER_MODULE(Counter);
