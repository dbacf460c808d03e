// Verification with variables shared with other subsystems: an import counts as produced with
// its declared shape (eq. 2, rule 3), an import beside a local producer is two producers (eq. 1),
// and an export must have a producer in the file.

#include <gtest/gtest.h>

#include "unit/config/checked_file.hpp"

namespace chimera {
namespace {

using test::CheckedFile;
using test::messages;

// Figure 8's vision side without its sensor: x_m comes from the robot's machine.
constexpr const char* kVision = R"(subsystem: vision_side
tasks:
  - {name: vision, module: visual_servo}
exports: [x_d]
)";

TEST(VerifyRemote, WithoutItsImportTheVisionTaskLacksItsInput) {
  const auto v = CheckedFile(kVision).verify();
  ASSERT_EQ(v.size(), 1U) << testing::PrintToString(messages(v));
  EXPECT_EQ(v[0].rule, 2);
  EXPECT_EQ(v[0].variable, "x_m");
}

TEST(VerifyRemote, AnImportCountsAsProduced) {
  const CheckedFile f(std::string(kVision) + "imports:\n  x_m: { type: f64, count: 6, max_age: 50ms }\n");
  EXPECT_TRUE(f.verify().empty()) << testing::PrintToString(messages(f.verify()));
  // The import is a variable of the global table, with its declared shape.
  const auto& vars = f.resolved().variables;
  const auto x_m = std::find_if(vars.begin(), vars.end(), [](const VarSpec& s) { return s.name == "x_m"; });
  ASSERT_NE(x_m, vars.end());
  EXPECT_EQ(x_m->shape, (VarShape{ElemType::kF64, 6}));
}

TEST(VerifyRemote, AnImportOfTheWrongSizeBreaksRule3) {
  const CheckedFile f(std::string(kVision) + "imports:\n  x_m: { type: f64, count: 7, max_age: 50ms }\n");
  const auto v = f.verify();
  ASSERT_FALSE(v.empty());
  EXPECT_EQ(v.front().rule, 3);
  EXPECT_EQ(v.front().message,
            "rule 3: variable x_m is f64[7] in imports and f64[6] in task vision (port x_m); the global table "
            "holds one shape per variable");
}

TEST(VerifyRemote, ImportingWhatALocalTaskProducesBreaksRule1) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: vision, module: visual_servo}
  - {name: fk, module: fwd_kin_jacobian}
  - {name: robot, module: robot_position}
configurations:
  local: [vision, robot]
  both: [vision, fk, robot]
imports:
  x_m: { type: f64, count: 6, max_age: 50ms }
  theta_d: { type: f64, count: 6, max_age: 50ms }
)");
  // In `local` the import is x_m's one producer; in `both` fk produces it as well.
  const auto v = f.verify();
  ASSERT_EQ(v.size(), 1U) << testing::PrintToString(messages(v));
  EXPECT_EQ(v[0].rule, 1);
  EXPECT_EQ(v[0].configuration, "both");
  EXPECT_EQ(v[0].tasks, (std::vector<std::string>{"fk"}));
  EXPECT_EQ(v[0].message, "configuration 'both': rule 1: x_m is produced by fk and by imports");
}

TEST(VerifyRemote, ImportingAConstantBreaksRule1) {
  const CheckedFile f(R"(subsystem: s
constants: { x_m: [0, 0, 0, 0, 0, 0] }
tasks:
  - {name: vision, module: visual_servo}
imports:
  x_m: { type: f64, count: 6, max_age: 50ms }
)");
  const auto v = f.verify();
  ASSERT_EQ(v.size(), 1U) << testing::PrintToString(messages(v));
  EXPECT_EQ(v[0].message, "configuration 'default': rule 1: x_m is produced by constants and imports");
}

TEST(VerifyRemote, ExportingWhatNothingProducesIsRefused) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: vision, module: visual_servo}
imports:
  x_m: { type: f64, count: 6, max_age: 50ms }
exports: [x_d, x_goal]
)");
  const auto v = f.verify();
  ASSERT_EQ(v.size(), 1U) << testing::PrintToString(messages(v));
  EXPECT_EQ(v[0].rule, 2);
  EXPECT_EQ(v[0].variable, "x_goal");
  EXPECT_EQ(v[0].message, "rule 2: x_goal is exported (line 6) but no task or constant of the file produces it");
}

TEST(VerifyRemote, ExportingAVariableThatOnlyTasksReadIsRefused) {
  // vision reads x_m; reading is not producing.
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: vision, module: visual_servo}
  - {name: fk, module: fwd_kin_jacobian}
  - {name: robot, module: robot_position}
imports:
  theta_d: { type: f64, count: 6, max_age: 50ms }
exports: [x_m, jacobian, ndof]
)");
  EXPECT_TRUE(f.verify().empty()) << testing::PrintToString(messages(f.verify()));
  const CheckedFile reader_only(R"(subsystem: s
tasks:
  - {name: vision, module: visual_servo}
exports: [x_m]
)");
  const auto v = reader_only.verify();
  ASSERT_FALSE(v.empty());
  EXPECT_EQ(v.front().message, "rule 2: x_m is exported (line 4) but no task or constant of the file produces it");
}

}  // namespace
}  // namespace chimera
