#include "chimera/control/command.hpp"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace chimera {
namespace {

Command parsed(std::string_view line) {
  auto c = parse_command(line);
  EXPECT_TRUE(c.ok()) << line << ": " << (c.ok() ? "" : c.error().message);
  return c.ok() ? *c : Command{};
}

std::string refusal(std::string_view line) {
  auto c = parse_command(line);
  EXPECT_FALSE(c.ok()) << line;
  if (c.ok()) return {};
  EXPECT_EQ(c.error().code, Errc::kInvalidInput);
  return c.error().message;
}

TEST(ParseCommand, EveryVerb) {
  struct Case {
    std::string line;
    Verb verb;
    std::vector<std::string> args;
  };
  const std::vector<Case> cases{
      {"status", Verb::kStatus, {}},
      {"spawn pid", Verb::kSpawn, {"pid"}},
      {"on pid robot", Verb::kOn, {"pid", "robot"}},
      {"off traj", Verb::kOff, {"traj"}},
      {"kill pid", Verb::kKill, {"pid"}},
      {"clear robot", Verb::kClear, {"robot"}},
      {"get theta_m", Verb::kGet, {"theta_m"}},
      {"set theta_d 0 0.5", Verb::kSet, {"theta_d", "0", "0.5"}},
      {"wait 1s", Verb::kWait, {"1s"}},
      {"stats", Verb::kStats, {}},
      {"quit", Verb::kQuit, {}},
      {"help", Verb::kHelp, {}},
  };
  for (const auto& c : cases) {
    const Command command = parsed(c.line);
    EXPECT_EQ(command.verb, c.verb) << c.line;
    EXPECT_EQ(command.args, c.args) << c.line;
    EXPECT_EQ(verb_name(command.verb), c.line.substr(0, c.line.find(' ')));
  }
}

TEST(ParseCommand, SplitsAtAnyWhitespace) {
  const Command c = parsed("  on\tpid   robot \r");
  EXPECT_EQ(c.verb, Verb::kOn);
  EXPECT_EQ(c.args, (std::vector<std::string>{"pid", "robot"}));
}

TEST(ParseCommand, SetCarriesItsNumbers) {
  const Command c = parsed("set theta_d 1 -2.5 +3 1e-3");
  EXPECT_EQ(c.values, (std::vector<double>{1.0, -2.5, 3.0, 1e-3}));
}

TEST(ParseCommand, WaitCarriesItsDuration) {
  EXPECT_EQ(parsed("wait 1s").duration_ns, 1'000'000'000);
  EXPECT_EQ(parsed("wait 250ms").duration_ns, 250'000'000);
  EXPECT_EQ(parsed("wait 20us").duration_ns, 20'000);
  EXPECT_EQ(parsed("wait 7ns").duration_ns, 7);
}

TEST(ParseCommand, UnknownVerbSaysTryHelp) {
  EXPECT_EQ(refusal("swap near_singularity"), "unknown command 'swap' (try help)");
  EXPECT_EQ(refusal("STATUS"), "unknown command 'STATUS' (try help)");
}

TEST(ParseCommand, EmptyLineIsNoCommand) {
  EXPECT_FALSE(refusal("").empty());
  EXPECT_FALSE(refusal("   ").empty());
}

TEST(ParseCommand, BadArityNamesTheUsage) {
  for (const char* line :
       {"status now", "spawn", "spawn a b", "on", "off", "kill", "kill a b", "clear", "clear a b", "get", "get a b",
        "set", "set theta_d", "wait", "wait 1s 2s", "stats a b", "quit now", "help on"}) {
    const std::string message = refusal(line);
    EXPECT_NE(message.find("usage:"), std::string::npos) << line << ": " << message;
  }
  EXPECT_EQ(refusal("kill a b"), "kill takes 1 argument (usage: kill TASK)");
  EXPECT_EQ(refusal("on"), "on takes at least 1 argument (usage: on TASK..)");
  EXPECT_EQ(refusal("status x"), "status takes no arguments (usage: status)");
  EXPECT_EQ(refusal("stats a b"), "stats takes at most 1 argument (usage: stats [TASK])");
}

TEST(ParseCommand, BadDurations) {
  for (const char* line : {"wait 10", "wait ten", "wait 1h", "wait ms", "wait -5ms", "wait 1.5.2s"}) {
    const std::string message = refusal(line);
    EXPECT_EQ(message.rfind("wait: ", 0), 0U) << line << ": " << message;
  }
  // "10 ms" is two words: the arity check speaks first.
  EXPECT_NE(refusal("wait 10 ms").find("usage: wait DURATION"), std::string::npos);
}

TEST(ParseCommand, BadNumbers) {
  EXPECT_EQ(refusal("set theta_d 1 abc"), "set: 'abc' is not a number");
  EXPECT_EQ(refusal("set theta_d 1x"), "set: '1x' is not a number");
  EXPECT_EQ(refusal("set theta_d nan"), "set: 'nan' is not a number");
  EXPECT_EQ(refusal("set theta_d 1e999"), "set: '1e999' is not a number");
}

TEST(ParseCommand, BlankAndCommentLines) {
  EXPECT_TRUE(is_blank_or_comment(""));
  EXPECT_TRUE(is_blank_or_comment(" \t"));
  EXPECT_TRUE(is_blank_or_comment("# a comment"));
  EXPECT_TRUE(is_blank_or_comment("   # indented"));
  EXPECT_FALSE(is_blank_or_comment("status # trailing"));
}

TEST(ParseCommand, HelpCoversEveryVerb) {
  std::vector<std::string_view> verbs;
  for (const auto& h : verb_help()) verbs.push_back(verb_name(h.verb));
  EXPECT_EQ(verbs.size(),
            20U);  // the 13 of the shell, live assembly's add, define, verify, remove, save, open, and dump
  for (const char* assembly : {"add", "define", "verify", "remove", "save", "open", "dump"})
    EXPECT_NE(std::find(verbs.begin(), verbs.end(), assembly), verbs.end()) << assembly;
  for (const auto& h : verb_help()) EXPECT_FALSE(h.does.empty());
  EXPECT_NE(std::find(verbs.begin(), verbs.end(), "switch"), verbs.end());
  EXPECT_EQ(parsed("switch near_singularity").args, (std::vector<std::string>{"near_singularity"}));
}

}  // namespace
}  // namespace chimera
