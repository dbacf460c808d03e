// chimera profile: runs a configuration, writes the budgets it measured, and chimera analyze
// --wcet-from takes them (issue 3, item 5). Times are the machine's: only their presence and
// the round trip are asserted, never their size.

#include <string>

#include <gtest/gtest.h>

#include "run_chimera.hpp"

namespace chimera::test {
namespace {

const std::string kData = CLI_DATA_DIR;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

class ProfileTest : public ::testing::Test {
 protected:
  Outcome chimera(const std::string& args) { return run_chimera(dir_, args); }
  [[nodiscard]] std::string path(const std::string& name) const { return dir_.file(name); }

 private:
  TempDir dir_;
};

TEST_F(ProfileTest, WritesBudgetsThatAnalyzeReads) {
  for (const char* clock : {"virtual", "real"}) {
    const std::string out = path(std::string("wcet_") + clock + ".yaml");
    const auto p =
        chimera("profile " + quoted(kData + "/fig4.yaml") + " --for 300ms --clock " + clock + " -o " + quoted(out));
    EXPECT_EXIT_CODE(p, 0);
    EXPECT_TRUE(contains(p.out, "configuration 'pid_control' ran 300.00 ms on the " + std::string(clock) + " clock"))
        << p.out;
    const std::string text = read_text(out);
    EXPECT_TRUE(contains(text, "subsystem: cli_fig4\n")) << text;
    EXPECT_TRUE(contains(text, std::string("clock: ") + clock + "\n")) << text;
    for (const char* task : {"traj", "pid", "robot"})
      EXPECT_TRUE(contains(text, std::string("  ") + task + ": { wcet: "));
    const auto a = chimera("analyze " + quoted(kData + "/fig4.yaml") + " --wcet-from " + quoted(out));
    EXPECT_TRUE(a.exit_code == 0 || a.exit_code == 1) << a.err;  // feasible or not is the machine's to say
    EXPECT_TRUE(contains(a.out, " profile ")) << "every C came from the profile:\n" << a.out;
    EXPECT_FALSE(contains(a.out, " measured ")) << a.out;
  }
}

TEST_F(ProfileTest, BadInputIsExitTwo) {
  EXPECT_EXIT_CODE(chimera("profile " + quoted(kData + "/fig4.yaml")), 2);  // no -o
  EXPECT_EXIT_CODE(chimera("profile " + quoted(kData + "/fig4.yaml") + " -o x.yaml --config nope"), 2);
  EXPECT_EXIT_CODE(chimera("profile nowhere.yaml -o x.yaml"), 2);
  EXPECT_EXIT_CODE(chimera("profile " + quoted(kData + "/fig4.yaml") + " -o x.yaml --margin 0.5"), 2);
}

}  // namespace
}  // namespace chimera::test
