// The teleoperation commands (modules/teleop_input/teleop_command.hpp): what is read and what is
// refused.

#include "teleop_input/teleop_command.hpp"

#include <gtest/gtest.h>

namespace chimera::modules::teleop {
namespace {

TEST(TeleopCommand, ReadsEachVerb) {
  Command c;
  ASSERT_TRUE(parse_command("move 0.01 -0.02 +0.03", c));
  EXPECT_EQ(c.verb, Verb::kMove);
  EXPECT_EQ(c.values, (std::array<double, 6>{0.01, -0.02, 0.03, 0, 0, 0}));
  ASSERT_TRUE(parse_command("  move 0 0 0 0.1 0.2 0.3\r\n", c));
  EXPECT_EQ(c.values, (std::array<double, 6>{0, 0, 0, 0.1, 0.2, 0.3}));
  ASSERT_TRUE(parse_command("goto 0.5, 0, 0.5, 0, 2.356, 0", c));
  EXPECT_EQ(c.verb, Verb::kGoto);
  EXPECT_EQ(c.values[4], 2.356);
  ASSERT_TRUE(parse_command("vel 0.05 0 0", c));
  EXPECT_EQ(c.verb, Verb::kVel);
  for (const auto& [text, verb] : {std::pair{"stop", Verb::kStop}, {"hold", Verb::kHold}, {"home", Verb::kHome}}) {
    ASSERT_TRUE(parse_command(text, c)) << text;
    EXPECT_EQ(c.verb, verb) << text;
  }
}

TEST(TeleopCommand, RefusesWhatIsNotACommand) {
  Command c;
  for (const char* bad : {"", "jump 1 2 3", "move 1 2", "move 1 2 3 4", "move 1 2 3 4 5 6 7", "goto 1 2 3",
                          "move 1 two 3", "move 1 2 nan", "move 1 2 inf", "stop now", "MOVE 1 2 3", "move 1 2 3x"})
    EXPECT_FALSE(parse_command(bad, c)) << '"' << bad << '"';
}

}  // namespace
}  // namespace chimera::modules::teleop
