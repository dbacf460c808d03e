// Resolution: ports bound to variables after renaming, sizes fixed from ndof, the global table's
// variables, and the file-wide problems (one shape per variable, one value per size constant).

#include <gtest/gtest.h>

#include "unit/config/checked_file.hpp"

namespace chimera {
namespace {

using test::CheckedFile;
using test::messages;

const std::string kData = CHIMERA_CONFIG_TEST_DATA;

VarShape f64(std::uint32_t n) { return VarShape{ElemType::kF64, n}; }

TEST(ResolveSubsystem, Figure4BindsEveryPortWithItsSize) {
  const auto f = CheckedFile::from_file(kData + "/figure4.yaml");
  EXPECT_TRUE(f.resolution().violations.empty()) << testing::PrintToString(messages(f.resolution().violations));
  const ResolvedTask* pid = f.resolved().find_task("pid");
  ASSERT_NE(pid, nullptr);
  EXPECT_TRUE(pid->sized);
  EXPECT_EQ(pid->module->name, "pid_joint");
  ASSERT_EQ(pid->bindings.size(), 6U);  // declaration order
  EXPECT_EQ(pid->bindings[0].port, "ndof");
  EXPECT_EQ(pid->bindings[0].kind, PortKind::kInConst);
  EXPECT_EQ(pid->bindings[0].shape, f64(1));
  EXPECT_EQ(pid->bindings[5].port, "tau_r");
  EXPECT_EQ(pid->bindings[5].variable, "tau_r");
  EXPECT_EQ(pid->bindings[5].kind, PortKind::kOutVar);
  EXPECT_EQ(pid->bindings[5].shape, f64(6));
  // The robot sizes its own ports by the ndof it publishes.
  EXPECT_EQ(f.binding("robot", "theta_m").shape, f64(6));
  EXPECT_EQ(f.binding("robot", "ndof").kind, PortKind::kOutConst);
  EXPECT_EQ(f.binding("traj", "theta_d").shape, f64(6));
}

TEST(ResolveSubsystem, VariablesAreTheSortedUnionWithTheirShapes) {
  const auto f = CheckedFile::from_file(kData + "/figure4.yaml");
  std::vector<std::string> names;
  for (const auto& v : f.resolved().variables) names.push_back(v.name);
  EXPECT_EQ(names, (std::vector<std::string>{"dtheta_d", "dtheta_m", "ndof", "tau_r", "theta_d", "theta_m"}));
  for (const auto& v : f.resolved().variables) EXPECT_EQ(v.shape, f64(v.name == "ndof" ? 1 : 6)) << v.name;
  ASSERT_EQ(f.resolved().constant_values.size(), 1U);
  EXPECT_EQ(f.resolved().constant_values[0].first, "ndof");
  EXPECT_EQ(f.resolved().constant_values[0].second, (std::vector<double>{6}));
}

TEST(ResolveSubsystem, JacobianIsSixTimesNdof) {
  const auto f = CheckedFile::from_file(kData + "/figures8_9.yaml");
  EXPECT_TRUE(f.resolution().violations.empty()) << testing::PrintToString(messages(f.resolution().violations));
  EXPECT_EQ(f.binding("fk", "jacobian").shape, f64(36));
  EXPECT_EQ(f.binding("dls", "jacobian").shape, f64(36));
  EXPECT_EQ(f.binding("fk", "x_m").shape, f64(6));
  EXPECT_EQ(f.binding("integ", "theta_d").shape, f64(6));
  // `constants:` entries are variables of the global table too.
  const auto& vars = f.resolved().variables;
  const auto payload = std::find_if(vars.begin(), vars.end(), [](const VarSpec& v) { return v.name == "payload_kg"; });
  ASSERT_NE(payload, vars.end());
  EXPECT_EQ(payload->shape, f64(1));
}

TEST(ResolveSubsystem, SevenDofArmResizesEveryDependentPort) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: fk, module: fwd_kin_jacobian}
  - {name: robot, module: robot_position, params: {dof: 7}}
)");
  EXPECT_EQ(f.binding("fk", "jacobian").shape, f64(42));
  EXPECT_EQ(f.binding("fk", "theta_m").shape, f64(7));
  EXPECT_EQ(f.binding("robot", "theta_d").shape, f64(7));
}

TEST(ResolveSubsystem, ConstantsSizePortsToo) {
  const CheckedFile f(R"(subsystem: s
constants: { ndof: 4 }
tasks:
  - {name: traj, module: joint_traj_gen}
)");
  EXPECT_TRUE(f.resolved().find_task("traj")->sized);
  EXPECT_EQ(f.binding("traj", "dtheta_d").shape, f64(4));
}

TEST(ResolveSubsystem, SizesFollowARenamedSizeConstant) {
  const CheckedFile f(R"(subsystem: s
constants: { ndof_left: 3, ndof: 6 }
tasks:
  - name: left
    module: joint_traj_gen
    rename: { ndof: ndof_left, theta_d: theta_left, dtheta_d: dtheta_left }
  - {name: right, module: joint_traj_gen}
)");
  EXPECT_EQ(f.binding("left", "theta_d").variable, "theta_left");
  EXPECT_EQ(f.binding("left", "theta_d").shape, f64(3));
  EXPECT_EQ(f.binding("right", "theta_d").shape, f64(6));
  EXPECT_TRUE(f.resolution().violations.empty()) << testing::PrintToString(messages(f.resolution().violations));
}

TEST(ResolveSubsystem, NoValueLeavesTheTaskUnsizedWithoutAFileWideViolation) {
  const CheckedFile f("subsystem: s\ntasks:\n  - {name: traj, module: joint_traj_gen}\n");
  const ResolvedTask* traj = f.resolved().find_task("traj");
  ASSERT_NE(traj, nullptr);
  EXPECT_FALSE(traj->sized);
  EXPECT_EQ(f.binding("traj", "theta_d").shape.count, 0U);
  EXPECT_TRUE(f.resolution().violations.empty());
}

TEST(ResolveSubsystem, TwoValuesOfOneSizeConstantIsAFileWideViolation) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: traj, module: joint_traj_gen}
  - {name: arm6, module: robot_position}
  - name: arm7
    module: robot_position
    params: { dof: 7 }
    rename: { theta_d: theta_d7, theta_m: theta_m7, dtheta_m: dtheta_m7 }
configurations:
  six: [traj, arm6]
)");
  ASSERT_EQ(f.resolution().violations.size(), 1U) << testing::PrintToString(messages(f.resolution().violations));
  const Violation& v = f.resolution().violations[0];
  EXPECT_EQ(v.rule, 3);
  EXPECT_EQ(v.configuration, "");
  EXPECT_EQ(v.variable, "ndof");
  EXPECT_EQ(v.tasks, (std::vector<std::string>{"arm6", "arm7"}));
  EXPECT_EQ(v.message, "rule 3: ndof sizes ports but has different values in the file: 6 from arm6 and 7 from arm7");
  // verify_subsystem reports it even though each configuration is fine on its own.
  EXPECT_EQ(messages(f.verify()), messages(f.resolution().violations));
}

TEST(ResolveSubsystem, ASizeThatIsNotAWholeNumber) {
  const CheckedFile f("subsystem: s\nconstants: { ndof: 2.5 }\ntasks:\n  - {name: traj, module: joint_traj_gen}\n");
  EXPECT_FALSE(f.resolved().find_task("traj")->sized);
  EXPECT_EQ(messages(f.resolution().violations),
            (std::vector<std::string>{
                "rule 3: ndof = 2.5 cannot size port theta_d of task traj (it needs a whole number from 1 to 1048576)",
                "rule 3: ndof = 2.5 cannot size port dtheta_d of task traj (it needs a whole number from 1 to "
                "1048576)"}));
}

TEST(ResolveSubsystem, OneVariableWithTwoShapesInTheFile) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: robot, module: robot_position}
  - {name: log, module: f32_logger}
configurations:
  run: [robot]
  logging: [robot, log]
)");
  ASSERT_EQ(f.resolution().violations.size(), 1U) << testing::PrintToString(messages(f.resolution().violations));
  const Violation& v = f.resolution().violations[0];
  EXPECT_EQ(v.rule, 3);
  EXPECT_EQ(v.variable, "theta_m");
  EXPECT_EQ(v.tasks, (std::vector<std::string>{"robot", "log"}));
  EXPECT_EQ(
      v.message,
      "rule 3: variable theta_m is f64[6] in task robot (port theta_m) and f32[6] in task log (port theta_m); the "
      "global table holds one shape per variable");
}

TEST(ResolveSubsystem, AConstantAndAPortWithTwoShapes) {
  const CheckedFile f("subsystem: s\nconstants: { x_d: [1, 2] }\ntasks:\n  - {name: v, module: visual_servo}\n");
  EXPECT_EQ(messages(f.resolution().violations),
            (std::vector<std::string>{"rule 3: variable x_d is f64[2] in constants and f64[6] in task v (port x_d); "
                                      "the global table holds one shape per variable"}));
}

TEST(ResolveSubsystem, ASizeByAPortTheModuleDoesNotHave) {
  const CheckedFile f("subsystem: s\ntasks:\n  - {name: b, module: bad_sized}\n");
  EXPECT_FALSE(f.resolved().find_task("b")->sized);
  ASSERT_EQ(f.resolution().violations.size(), 1U);
  EXPECT_EQ(f.resolution().violations[0].rule, 0);
  EXPECT_EQ(f.resolution().violations[0].message,
            "task b: module bad_sized sizes port y by missing_symbol, which is not one of its const ports");
}

TEST(ResolveSubsystem, AFollowingPortTakesTheSizeItsProducerGives) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: robot, module: robot_position, params: {dof: 7}}
  - {name: log, module: any_logger}
configurations:
  logging: [robot, log]
)");
  EXPECT_TRUE(f.resolution().violations.empty()) << testing::PrintToString(messages(f.resolution().violations));
  EXPECT_TRUE(f.resolved().find_task("log")->sized);
  EXPECT_EQ(f.binding("log", "theta_m").shape, f64(7));
}

TEST(ResolveSubsystem, AFollowingPortTakesAConstantsSize) {
  const CheckedFile f("subsystem: s\nconstants: { theta_m: [1, 2, 3] }\ntasks:\n  - {name: log, module: any_logger}\n");
  EXPECT_TRUE(f.resolution().violations.empty()) << testing::PrintToString(messages(f.resolution().violations));
  EXPECT_EQ(f.binding("log", "theta_m").shape, f64(3));
}

TEST(ResolveSubsystem, AFollowingPortWithNothingToFollow) {
  const CheckedFile f("subsystem: s\ntasks:\n  - {name: log, module: any_logger}\n");
  EXPECT_FALSE(f.resolved().find_task("log")->sized);
  ASSERT_EQ(f.resolution().violations.size(), 1U);
  EXPECT_EQ(f.resolution().violations[0].rule, 3);
  EXPECT_EQ(f.resolution().violations[0].message,
            "rule 3: port theta_m of task log takes its size from variable theta_m, but no other task or constant of "
            "the file gives theta_m a size");
}

TEST(ResolveSubsystem, AHandBuiltSpecWithAnUnknownModule) {
  SubsystemSpec spec;
  spec.name = "s";
  spec.tasks.push_back(TaskSpec{});
  spec.tasks[0].name = "t";
  spec.tasks[0].module = "nowhere";
  const Resolution r = resolve_subsystem(spec, test::config_test_registry());
  ASSERT_EQ(r.subsystem.tasks.size(), 1U);
  EXPECT_FALSE(r.subsystem.tasks[0].sized);
  EXPECT_EQ(messages(r.violations), (std::vector<std::string>{"task t: no module named nowhere in the library"}));
}

}  // namespace
}  // namespace chimera
