// LocalTable: binding to the global table, typed views and their errors, the four transfers and
// reset, on the paper's Figure 4 (trajectory generator -> PID controller -> robot interface).

#include "chimera/svt/local_table.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "unit/svt/svt_test_support.hpp"

namespace chimera {
namespace {

constexpr VarShape kJoints{ElemType::kF64, 6};

class LocalTableTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::vector<VarSpec> vars{
        {"theta_d", kJoints},           {"theta_m", kJoints},          {"tau_r", kJoints},
        {"gains", {ElemType::kF64, 3}}, {"ndof", {ElemType::kI32, 1}}, {"mask", {ElemType::kU8, 3}}};
    auto t = GlobalTable::create(test::unique_subsystem("local"), vars);
    ASSERT_TRUE(t) << t.error().message;
    global_.emplace(std::move(*t));
  }

  std::vector<PortBinding> pid_ports() const {
    // The PID module calls its ports by its own names; the configuration renamed them.
    return {{"q_ref", "theta_d", PortKind::kInVar, kJoints},
            {"q", "theta_m", PortKind::kInVar, kJoints},
            {"mask", "mask", PortKind::kInVar, {ElemType::kU8, 3}},
            {"kp_ki_kd", "gains", PortKind::kInConst, {ElemType::kF64, 3}},
            {"tau", "tau_r", PortKind::kOutVar, kJoints},
            {"ndof", "ndof", PortKind::kOutConst, {ElemType::kI32, 1}}};
  }
  std::vector<PortBinding> generator_ports() const {
    return {{"out", "theta_d", PortKind::kOutVar, kJoints},
            {"gains", "gains", PortKind::kOutConst, {ElemType::kF64, 3}},
            {"mask", "mask", PortKind::kOutVar, {ElemType::kU8, 3}},
            {"tau", "tau_r", PortKind::kInVar, kJoints},
            {"ndof", "ndof", PortKind::kInConst, {ElemType::kI32, 1}}};
  }
  LocalTable make(const std::vector<PortBinding>& ports) {
    auto t = LocalTable::create(*global_, ports);
    EXPECT_TRUE(t) << t.error().message;
    return std::move(*t);
  }

  std::optional<GlobalTable> global_;
};

TEST_F(LocalTableTest, CreateNamesThePortAndVariableOfABadBinding) {
  std::vector<PortBinding> unknown{{"q_ref", "theta_x", PortKind::kInVar, kJoints}};
  auto a = LocalTable::create(*global_, unknown);
  ASSERT_FALSE(a);
  EXPECT_EQ(a.error().code, Errc::kNotFound);
  EXPECT_NE(a.error().message.find("port 'q_ref'"), std::string::npos) << a.error().message;
  EXPECT_NE(a.error().message.find("'theta_x'"), std::string::npos) << a.error().message;

  std::vector<PortBinding> mismatch{{"q_ref", "theta_d", PortKind::kInVar, {ElemType::kF64, 7}}};
  auto b = LocalTable::create(*global_, mismatch);
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().code, Errc::kIllegal);
  EXPECT_EQ(b.error().message, "port 'q_ref' is f64[7] but state variable 'theta_d' is f64[6]");

  std::vector<PortBinding> twice{{"q", "theta_d", PortKind::kInVar, kJoints},
                                 {"q", "theta_m", PortKind::kInVar, kJoints}};
  auto c = LocalTable::create(*global_, twice);
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().message.find("port 'q' is declared twice"), std::string::npos) << c.error().message;
}

TEST_F(LocalTableTest, ViewErrorsNameThePort) {
  LocalTable pid = make(pid_ports());
  auto missing = pid.input<double>("theta_d");  // the variable's name, not the port's
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, Errc::kNotFound);
  EXPECT_EQ(missing.error().message, "port 'theta_d' does not exist");

  auto wrong_kind = pid.input<double>("tau");
  ASSERT_FALSE(wrong_kind);
  EXPECT_EQ(wrong_kind.error().message, "port 'tau' is an output; use out<>()");
  auto wrong_kind_out = pid.output<double>("q_ref");
  ASSERT_FALSE(wrong_kind_out);
  EXPECT_EQ(wrong_kind_out.error().message, "port 'q_ref' is an input; use in<>()");

  auto wrong_type = pid.input<float>("q_ref");
  ASSERT_FALSE(wrong_type);
  EXPECT_EQ(wrong_type.error().message, "port 'q_ref' holds f64, not f32");
  auto wrong_type_out = pid.output<std::int64_t>("ndof");
  ASSERT_FALSE(wrong_type_out);
  EXPECT_EQ(wrong_type_out.error().message, "port 'ndof' holds i32, not i64");

  // Constants are inputs and outputs like the variables are.
  EXPECT_TRUE(pid.input<double>("kp_ki_kd"));
  EXPECT_TRUE(pid.output<std::int32_t>("ndof"));
  EXPECT_TRUE(pid.input<bool>("mask"));
  EXPECT_TRUE(pid.input<std::uint8_t>("mask"));
}

TEST_F(LocalTableTest, ViewsAreSizedAlignedAndStartAtNoData) {
  LocalTable pid = make(pid_ports());
  In<std::uint8_t> mask = *pid.input<std::uint8_t>("mask");
  In<double> gains = *pid.input<double>("kp_ki_kd");  // follows a 3-byte port
  Out<std::int32_t> ndof = *pid.output<std::int32_t>("ndof");
  EXPECT_EQ(mask.size(), 3U);
  EXPECT_EQ(gains.size(), 3U);
  EXPECT_EQ(ndof.size(), 1U);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(gains.values().data()) % alignof(double), 0U);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(ndof.values().data()) % 8, 0U);
  EXPECT_TRUE(gains.bound());
  EXPECT_FALSE(gains.has_data());
  EXPECT_EQ(gains.freshness(), Freshness::kNoData);
  for (double g : gains.values()) EXPECT_EQ(g, 0.0);
  EXPECT_EQ(pid.ports().size(), pid_ports().size());
  EXPECT_EQ(pid.ports()[0].port, "q_ref");
}

TEST_F(LocalTableTest, StartsAtZeroOnADirtyHeap) {
  // Storage padding once came back with heap garbage in it: free dirty blocks of the storage's
  // size first, so the table is likely to be given one of them.
  for (int round = 0; round < 20; ++round) {
    { std::vector<std::byte> dirty(192, std::byte{0xff}); }
    LocalTable pid = make(pid_ports());
    for (const auto& name : {"q_ref", "q", "kp_ki_kd"}) {
      for (double x : pid.input<double>(name)->values()) ASSERT_EQ(x, 0.0) << name;
    }
    for (std::uint8_t x : pid.input<std::uint8_t>("mask")->values()) ASSERT_EQ(x, 0) << "mask";
    for (double x : pid.output<double>("tau")->values()) ASSERT_EQ(x, 0.0) << "tau";
    ASSERT_EQ((*pid.output<std::int32_t>("ndof"))[0], 0);
  }
}

TEST_F(LocalTableTest, VariablesFlowFromOutputsToInputsWithFreshness) {
  LocalTable gen = make(generator_ports());
  LocalTable pid = make(pid_ports());
  Out<double> gen_out = *gen.output<double>("out");
  Out<std::uint8_t> gen_mask = *gen.output<std::uint8_t>("mask");
  In<double> q_ref = *pid.input<double>("q_ref");
  In<double> q = *pid.input<double>("q");
  In<bool> mask = *pid.input<bool>("mask");
  Out<double> tau = *pid.output<double>("tau");
  In<double> gen_tau = *gen.input<double>("tau");

  pid.pull_in_vars();
  EXPECT_EQ(q_ref.freshness(), Freshness::kNoData);
  EXPECT_EQ(q.freshness(), Freshness::kNoData);

  for (std::size_t i = 0; i < 6; ++i) gen_out[i] = 0.1 * static_cast<double>(i);
  gen_mask[1] = 1;
  gen.push_out_vars(0);
  pid.pull_in_vars();
  EXPECT_EQ(q_ref.freshness(), Freshness::kNew);
  EXPECT_EQ(q.freshness(), Freshness::kNoData);  // nobody writes theta_m in this test
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(q_ref[i], 0.1 * static_cast<double>(i));
  EXPECT_FALSE(mask[0]);
  EXPECT_TRUE(mask[1]);

  pid.pull_in_vars();
  EXPECT_EQ(q_ref.freshness(), Freshness::kOld);
  EXPECT_EQ(q_ref[5], 0.5);  // old values stay

  gen_out[0] = 42;
  gen.push_out_vars(0);
  pid.pull_in_vars();
  EXPECT_EQ(q_ref.freshness(), Freshness::kNew);
  EXPECT_EQ(q_ref[0], 42.0);

  // The other direction, and a write that stays local until pushed.
  tau[2] = -3;
  gen.pull_in_vars();
  EXPECT_EQ(gen_tau.freshness(), Freshness::kNoData);
  pid.push_out_vars(0);
  gen.pull_in_vars();
  EXPECT_EQ(gen_tau.freshness(), Freshness::kNew);
  EXPECT_EQ(gen_tau[2], -3.0);
}

TEST_F(LocalTableTest, ConstantsMoveOnlyWithTheirOwnTransfers) {
  LocalTable gen = make(generator_ports());
  LocalTable pid = make(pid_ports());
  Out<double> gains_out = *gen.output<double>("gains");
  In<double> gains = *pid.input<double>("kp_ki_kd");
  Out<double> theta_d = *gen.output<double>("out");
  In<double> q_ref = *pid.input<double>("q_ref");

  gains_out[0] = 100;
  theta_d[0] = 1;
  gen.push_out_vars(0);  // variables only
  EXPECT_EQ(global_->version(*global_->find("gains")), 0U);
  gen.push_out_consts();
  EXPECT_EQ(global_->version(*global_->find("gains")), 1U);
  EXPECT_EQ(global_->version(*global_->find("theta_d")), 1U);

  pid.pull_in_vars();  // variables only
  EXPECT_EQ(gains.freshness(), Freshness::kNoData);
  EXPECT_EQ(gains[0], 0.0);
  EXPECT_EQ(q_ref[0], 1.0);
  pid.pull_in_consts();
  EXPECT_EQ(gains.freshness(), Freshness::kNew);
  EXPECT_EQ(gains[0], 100.0);
  pid.pull_in_consts();
  EXPECT_EQ(gains.freshness(), Freshness::kOld);

  Out<std::int32_t> ndof = *pid.output<std::int32_t>("ndof");
  In<std::int32_t> gen_ndof = *gen.input<std::int32_t>("ndof");
  ndof[0] = 6;
  pid.push_out_consts();
  gen.pull_in_consts();
  EXPECT_EQ(gen_ndof[0], 6);
}

TEST_F(LocalTableTest, ResetInputsZerosInputsForgetsWhatWasSeenAndKeepsOutputs) {
  LocalTable gen = make(generator_ports());
  LocalTable pid = make(pid_ports());
  Out<double> out = *gen.output<double>("out");
  In<double> q_ref = *pid.input<double>("q_ref");
  Out<double> tau = *pid.output<double>("tau");
  out[3] = 7;
  gen.push_out_vars(0);
  pid.pull_in_vars();
  tau[0] = 5;
  ASSERT_EQ(q_ref[3], 7.0);
  ASSERT_EQ(q_ref.freshness(), Freshness::kNew);

  pid.reset_inputs();
  EXPECT_EQ(q_ref[3], 0.0);
  EXPECT_EQ(tau[0], 5.0) << "outputs are the module's";
  EXPECT_EQ(q_ref.freshness(), Freshness::kNoData);
  // Having forgotten its version, the task gets the current value again, as new.
  pid.pull_in_vars();
  EXPECT_EQ(q_ref.freshness(), Freshness::kNew);
  EXPECT_EQ(q_ref[3], 7.0);
}

TEST_F(LocalTableTest, MovedTableKeepsItsViews) {
  auto created = LocalTable::create(*global_, pid_ports());
  ASSERT_TRUE(created);
  In<double> q_ref = *created->input<double>("q_ref");
  LocalTable moved = std::move(*created);
  LocalTable gen = make(generator_ports());
  (*gen.output<double>("out"))[1] = 9;
  gen.push_out_vars(0);
  moved.pull_in_vars();
  EXPECT_EQ(q_ref[1], 9.0);
  EXPECT_EQ(q_ref.freshness(), Freshness::kNew);
}

TEST_F(LocalTableTest, NoPortsIsFine) {
  LocalTable empty = make({});
  empty.pull_in_consts();
  empty.pull_in_vars();
  empty.push_out_vars(0);
  empty.push_out_consts();
  empty.reset_inputs();
  EXPECT_TRUE(empty.ports().empty());
}

}  // namespace
}  // namespace chimera
