// Verification of configurations: rules 1 (eq. 1), 2 (eq. 2) and 3 on the paper's figures and on
// configurations made to break each rule.

#include <gtest/gtest.h>

#include "unit/config/checked_file.hpp"

namespace chimera {
namespace {

using test::CheckedFile;
using test::messages;

const std::string kData = CHIMERA_CONFIG_TEST_DATA;

TEST(VerifySubsystem, Figure4IsLegal) {
  const auto f = CheckedFile::from_file(kData + "/figure4.yaml");
  EXPECT_TRUE(f.verify().empty()) << testing::PrintToString(messages(f.verify()));
}

TEST(VerifySubsystem, Figures8And9AreEachLegal) {
  const auto f = CheckedFile::from_file(kData + "/figures8_9.yaml");
  EXPECT_TRUE(f.verify().empty()) << testing::PrintToString(messages(f.verify()));
  EXPECT_TRUE(f.verify("standard").empty());
  EXPECT_TRUE(f.verify("near_singularity").empty());
}

TEST(VerifyTasks, TheUnionOfFigures8And9HasTwoProducersOfThetaD) {
  const auto f = CheckedFile::from_file(kData + "/figures8_9.yaml");
  const auto v = verify_tasks(f.resolved(), {"vision", "ik", "dls", "integ", "fk", "robot"}, "");
  ASSERT_EQ(v.size(), 1U) << testing::PrintToString(messages(v));
  EXPECT_EQ(v[0].rule, 1);
  EXPECT_EQ(v[0].variable, "theta_d");
  EXPECT_EQ(v[0].tasks, (std::vector<std::string>{"ik", "integ"}));
  EXPECT_EQ(v[0].configuration, "");
  EXPECT_EQ(v[0].message, "rule 1: theta_d is produced by ik and integ");
}

TEST(VerifyTasks, Rule1NamesTheConfigurationTheVariableAndBothTasks) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: vision, module: visual_servo}
  - {name: fk, module: fwd_kin_jacobian}
  - {name: ik, module: inv_kin}
  - {name: dls, module: damped_least_squares}
  - {name: integ, module: time_integrator}
  - {name: robot, module: robot_position}
configurations:
  both: [vision, fk, ik, dls, integ, robot]
)");
  const auto v = f.verify();
  ASSERT_EQ(v.size(), 1U) << testing::PrintToString(messages(v));
  EXPECT_EQ(v[0].rule, 1);
  EXPECT_EQ(v[0].configuration, "both");
  EXPECT_EQ(v[0].message, "configuration 'both': rule 1: theta_d is produced by ik and integ");
}

TEST(VerifyTasks, Rule1AgainstConstants) {
  const CheckedFile f(R"(subsystem: s
constants: { ndof: 6, theta_d: [0, 0, 0, 0, 0, 0] }
tasks:
  - {name: traj, module: joint_traj_gen}
)");
  const auto v = f.verify();
  ASSERT_EQ(v.size(), 1U) << testing::PrintToString(messages(v));
  EXPECT_EQ(v[0].tasks, (std::vector<std::string>{"traj"}));
  EXPECT_EQ(v[0].message, "configuration 'default': rule 1: theta_d is produced by traj and by constants");
}

TEST(VerifyTasks, Rule2WhenTheVisionTaskIsMissing) {
  const auto f = CheckedFile::from_file(kData + "/figures8_9.yaml");
  const auto v = verify_tasks(f.resolved(), {"fk", "ik", "robot"}, "blind");
  ASSERT_EQ(v.size(), 1U) << testing::PrintToString(messages(v));
  EXPECT_EQ(v[0].rule, 2);
  EXPECT_EQ(v[0].variable, "x_d");
  EXPECT_EQ(v[0].tasks, (std::vector<std::string>{"ik"}));
  EXPECT_EQ(v[0].message, "configuration 'blind': rule 2: x_d is consumed by ik but produced by no task");

  const auto both = verify_tasks(f.resolved(), {"fk", "ik", "dls", "integ", "robot"}, "");
  const auto x_d = std::find_if(both.begin(), both.end(), [](const Violation& x) { return x.variable == "x_d"; });
  ASSERT_NE(x_d, both.end());
  EXPECT_EQ(x_d->message, "rule 2: x_d is consumed by ik and dls but produced by no task");
}

TEST(VerifyTasks, Rule2ForASizeConstantNoTaskProduces) {
  const CheckedFile f("subsystem: s\ntasks:\n  - {name: traj, module: joint_traj_gen}\n");
  EXPECT_EQ(
      messages(f.verify()),
      (std::vector<std::string>{"configuration 'default': rule 2: ndof is consumed by traj but produced by no task"}));
}

TEST(VerifyTasks, Rule3NamesBothShapes) {
  // pid is sized for 6 joints by a constant, the robot publishes 7.
  const CheckedFile f(R"(subsystem: s
constants: { ndof6: 6 }
tasks:
  - {name: traj, module: joint_traj_gen, rename: {ndof: ndof6}}
  - {name: pid, module: pid_joint, rename: {ndof: ndof6}}
  - {name: robot, module: robot_torque, params: {dof: 7}}
)");
  const auto v = verify_tasks(f.resolved(), {"traj", "pid", "robot"}, "standard");
  EXPECT_EQ(messages(v), (std::vector<std::string>{
                             "configuration 'standard': rule 3: dtheta_m is f64[7] from robot but pid reads f64[6]",
                             "configuration 'standard': rule 3: tau_r is f64[6] from pid but robot reads f64[7]",
                             "configuration 'standard': rule 3: theta_m is f64[7] from robot but pid reads f64[6]"}));
  EXPECT_EQ(v[1].rule, 3);
  EXPECT_EQ(v[1].variable, "tau_r");
  EXPECT_EQ(v[1].tasks, (std::vector<std::string>{"pid", "robot"}));
}

TEST(VerifyTasks, Rule3OnElementType) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: robot, module: robot_position}
  - {name: traj, module: joint_traj_gen}
  - {name: log, module: f32_logger}
)");
  const auto v = verify_tasks(f.resolved(), {"robot", "traj", "log"}, "");
  EXPECT_EQ(messages(v), (std::vector<std::string>{"rule 3: theta_m is f64[6] from robot but log reads f32[6]"}));
}

TEST(VerifyTasks, FanOutIsLegal) {
  // theta_m feeds pid and fk, ndof feeds traj, pid and fk.
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: traj, module: joint_traj_gen}
  - {name: pid, module: pid_joint}
  - {name: robot, module: robot_torque}
  - {name: fk, module: fwd_kin_jacobian}
)");
  EXPECT_TRUE(f.verify().empty()) << testing::PrintToString(messages(f.verify()));
}

TEST(VerifyTasks, ConstantsSatisfyInputs) {
  const CheckedFile f(R"(subsystem: s
constants:
  ndof: 6
  x_d: [0.4, 0, 0.3, 0, 0, 0]
  theta_m: [0, 0, 0, 0, 0, 0]
tasks:
  - {name: ik, module: inv_kin}
  - {name: fk, module: fwd_kin_jacobian}
)");
  EXPECT_TRUE(f.verify().empty()) << testing::PrintToString(messages(f.verify()));
}

TEST(VerifyTasks, TwoGeneratorsWithoutAJoinBreakRule1) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: traj_a, module: joint_traj_gen}
  - {name: traj_b, module: joint_traj_gen}
  - {name: robot, module: robot_position}
)");
  EXPECT_EQ(messages(f.verify()),
            (std::vector<std::string>{"configuration 'default': rule 1: dtheta_d is produced by traj_a and traj_b",
                                      "configuration 'default': rule 1: theta_d is produced by traj_a and traj_b"}));
}

TEST(VerifyTasks, RenamesAndAJoinConnectorFixRule1) {
  const auto f = CheckedFile::from_file(kData + "/figure3_join.yaml");
  EXPECT_TRUE(f.verify().empty()) << testing::PrintToString(messages(f.verify()));
}

TEST(VerifyTasks, RenamedPortsAreNamedInMessages) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: traj, module: joint_traj_gen}
  - {name: ik, module: inv_kin, rename: {x_d: goal}}
  - {name: integ, module: time_integrator, rename: {theta_d: dtheta_d, dtheta_d: rate}}
  - {name: robot, module: robot_position}
)");
  EXPECT_EQ(messages(verify_tasks(f.resolved(), {"traj", "ik", "integ", "robot"}, "")),
            (std::vector<std::string>{"rule 1: dtheta_d is produced by traj and integ (port theta_d)",
                                      "rule 1: theta_d is produced by traj and ik",
                                      "rule 2: goal is consumed by ik (port x_d) but produced by no task",
                                      "rule 2: rate is consumed by integ (port dtheta_d) but produced by no task"}));
}

TEST(VerifyTasks, UnknownTaskNameIsRule0) {
  const auto f = CheckedFile::from_file(kData + "/figure4.yaml");
  const auto v = verify_tasks(f.resolved(), {"traj", "pid", "robot", "ghost"}, "c");
  ASSERT_EQ(v.size(), 1U);
  EXPECT_EQ(v[0].rule, 0);
  EXPECT_EQ(v[0].message, "configuration 'c': no task named ghost in the file");
}

TEST(VerifySubsystem, OnlyOneConfiguration) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: fk, module: fwd_kin_jacobian}
  - {name: ik, module: inv_kin}
  - {name: vision, module: visual_servo}
  - {name: robot, module: robot_position}
configurations:
  good: [vision, fk, ik, robot]
  blind: [fk, ik, robot]
)");
  EXPECT_TRUE(f.verify("good").empty());
  EXPECT_EQ(messages(f.verify("blind")),
            (std::vector<std::string>{"configuration 'blind': rule 2: x_d is consumed by ik but produced by no task"}));
  EXPECT_EQ(f.verify().size(), 1U);
}

TEST(VerifySubsystem, UnknownConfigurationName) {
  const auto f = CheckedFile::from_file(kData + "/figures8_9.yaml");
  const auto v = f.verify("fast");
  ASSERT_EQ(v.size(), 1U);
  EXPECT_EQ(v[0].rule, 0);
  EXPECT_EQ(v[0].configuration, "fast");
  EXPECT_EQ(v[0].message,
            kData + "/figures8_9.yaml: no configuration named fast (configurations: standard, near_singularity)");
  auto checked = check_configuration_name(f.spec(), "fast");
  ASSERT_FALSE(checked.ok());
  EXPECT_EQ(checked.error().code, Errc::kNotFound);
  EXPECT_EQ(checked.error().message, v[0].message);
  EXPECT_TRUE(check_configuration_name(f.spec(), "standard").ok());
}

TEST(VerifySubsystem, FileWideViolationsComeFirstThenConfigurationsInFileOrder) {
  const CheckedFile f(R"(subsystem: s
tasks:
  - {name: robot, module: robot_position}
  - {name: log, module: f32_logger}
  - {name: traj_a, module: joint_traj_gen}
  - {name: traj_b, module: joint_traj_gen}
configurations:
  zeta: [robot, traj_a, traj_b]
  alpha: [robot, log]
)");
  const std::string file_wide =
      "rule 3: variable theta_m is f64[6] in task robot (port theta_m) and f32[6] in task log (port theta_m); the "
      "global table holds one shape per variable";
  EXPECT_EQ(
      messages(f.verify()),
      (std::vector<std::string>{file_wide, "configuration 'zeta': rule 1: dtheta_d is produced by traj_a and traj_b",
                                "configuration 'zeta': rule 1: theta_d is produced by traj_a and traj_b",
                                "configuration 'alpha': rule 2: theta_d is consumed by robot but produced by no task",
                                "configuration 'alpha': rule 3: theta_m is f64[6] from robot but log reads f32[6]"}));
}

TEST(FormatViolations, OneLinePerViolation) {
  EXPECT_EQ(format_violations({}), "");
  const std::vector<Violation> v = {
      {1, "a", "x", {"p", "q"}, "configuration 'a': rule 1: x is produced by p and q"},
      {2, "a", "y", {"p"}, "configuration 'a': rule 2: y is consumed by p but produced by no task"}};
  EXPECT_EQ(format_violations(v),
            "configuration 'a': rule 1: x is produced by p and q\n"
            "configuration 'a': rule 2: y is consumed by p but produced by no task\n");
}

}  // namespace
}  // namespace chimera
