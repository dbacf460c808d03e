// join_weighted_average: the join connector of the paper's Figure 3. Two or more tasks that
// produce the same quantity have their outputs renamed to in_0, in_1, ...; the join publishes
// one weighted average of them, so that the quantity has a single producer again.

#include "module_docs/join_weighted_average.hpp"

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "chimera/module/registry.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

constexpr int kMaxInputs = 64;

// The number of inputs: the parameter inputs, or when it is 0 (its default) as many as there are
// weights, or 2.
int input_count(const Params& p) {
  double n = p.number("inputs", 0.0);
  if (n == 0.0) n = p.vector("weights").size() >= 2 ? static_cast<double>(p.vector("weights").size()) : 2.0;
  if (!(n >= 2.0) || n > kMaxInputs || n != std::floor(n)) return 2;
  return static_cast<int>(n);
}

std::string input_name(int i) { return "in_" + std::to_string(i); }

class JoinWeightedAverage final : public Module {
 public:
  static constexpr const char* kName = "join_weighted_average";
  static constexpr const char* kSummary = docs::join_weighted_average::kSummary;
  static constexpr const char* kDoc = docs::join_weighted_average::kText;

  static void declare(Declarations& d, const Params& p) {
    const int n = input_count(p);
    d.join_connector();
    for (int i = 0; i < n; ++i)
      d.in_var(input_name(i), Dim::follow(),
               "one producer's value of the quantity (rename it to that producer's variable)");
    d.out_var("out", Dim::follow(), "the weighted average: the one value of the quantity (rename it to its variable)");
    d.param("inputs", 0.0, "", "number of inputs in_0 ... in_{inputs-1}, from 2 to 64; 0: as many as weights, or 2")
        .whole()
        .at_least(0)
        .at_most(64);
    d.param("weights", Vector{}, "", "weight of each input, >= 0, not all 0; empty: equal weights").at_least(0);
  }

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    const double asked = p.number("inputs", 0.0);
    if (asked != 0.0 && (!(asked >= 2.0) || asked > kMaxInputs || asked != std::floor(asked)))
      return ctx.refuse("inputs", "join_weighted_average: inputs must be 0 or a whole number from 2 to 64");
    const int n = input_count(p);
    weights_ = p.vector("weights");
    if (weights_.empty()) weights_.assign(static_cast<std::size_t>(n), 1.0);
    if (weights_.size() != static_cast<std::size_t>(n))
      return ctx.refuse("weights", intern("join_weighted_average: " + std::to_string(weights_.size()) +
                                          " weights for " + std::to_string(n) + " inputs"));
    double total = 0.0;
    for (const double w : weights_) {
      if (!(w >= 0.0) || !std::isfinite(w))
        return ctx.refuse("weights", "join_weighted_average: weights must be >= 0 and finite");
      total += w;
    }
    if (!(total > 0.0)) return ctx.refuse("weights", "join_weighted_average: the weights must not all be 0");

    inputs_.clear();
    for (int i = 0; i < n; ++i) inputs_.push_back(ctx.in<double>(input_name(i)));
    out_ = ctx.out<double>("out");
    if (ctx.failed()) return Status::ok();  // InitContext names the port that did not bind
    for (int i = 0; i < n; ++i)
      if (inputs_[static_cast<std::size_t>(i)].size() != out_.size())
        return Status::fail(intern("join_weighted_average: " + input_name(i) + " has " +
                                   std::to_string(inputs_[static_cast<std::size_t>(i)].size()) +
                                   " elements but out has " + std::to_string(out_.size()) +
                                   "; a join averages values of one shape"));
    average();
    return Status::ok();
  }

  Status on() override {
    average();
    return Status::ok();
  }

  Status cycle() override {
    average();
    return Status::ok();
  }

 private:
  // out = sum(w_i in_i) / sum(w_i) over the inputs that have been written; until one has, out
  // keeps its value. An input whose producer has not run yet simply does not count.
  void average() noexcept {
    double total = 0.0;
    for (std::size_t k = 0; k < inputs_.size(); ++k)
      if (inputs_[k].has_data()) total += weights_[k];
    if (!(total > 0.0)) return;
    for (std::size_t e = 0; e < out_.size(); ++e) {
      double sum = 0.0;
      for (std::size_t k = 0; k < inputs_.size(); ++k)
        if (inputs_[k].has_data()) sum += weights_[k] * inputs_[k][e];
      out_[e] = sum / total;
    }
  }

  std::vector<In<double>> inputs_;  // sized in init
  Vector weights_;
  Out<double> out_;
};

CHIMERA_REGISTER_MODULE(JoinWeightedAverage);

}  // namespace
}  // namespace chimera::modules
