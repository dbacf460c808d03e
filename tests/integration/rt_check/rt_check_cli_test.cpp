// chimera run --rt-check as a module author uses it: a cycle that allocates is counted, cycle for
// cycle, in --stats-json and the timing table, and named once in an event; a task that keeps to
// the rules shows 0 in the same run; without the flag nothing is shown; Figure 4 counts nothing.

#include <unistd.h>

#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_chimera.hpp"
#include "support/json_text.hpp"

namespace chimera::test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

constexpr const char* kEvent = "hoarder: cycle() allocated on the real-time path (--rt-check)";

class RtCheckCliTest : public ::testing::Test {
 protected:
  Outcome chimera(const std::string& args) {
    return run_chimera(dir_, args, {}, "CHIMERA_MODULE_PATH=" + quoted(RT_CHECK_PLUGIN_DIR));
  }

  // Two tasks at 10 ms: one whose cycle allocates, one whose cycle does not.
  std::string two_tasks_file() {
    const std::string path = dir_.file("two.yaml");
    write_text(path, "subsystem: rt_check_" + std::to_string(::getpid()) +
                         "\n"
                         "plugins: [chimera_test_rt_check_modules]\n"
                         "tasks:\n"
                         "  - { name: quiet, module: test_quiet_counter, period: 10ms, rename: { y: u } }\n"
                         "  - { name: hoarder, module: test_hoarder, period: 10ms }\n");
    return path;
  }

  // Figure 4 as shipped, under a subsystem name no other test process uses.
  std::string fig4_file() {
    std::istringstream text(read_text(CHIMERA_EXAMPLES_DIR "/fig4_pid_joint.yaml"));
    std::string copy;
    for (std::string line; std::getline(text, line);) {
      if (line.rfind("subsystem:", 0) == 0) line = "subsystem: rt_check_fig4_" + std::to_string(::getpid());
      copy += line + "\n";
    }
    const std::string path = dir_.file("fig4.yaml");
    write_text(path, copy);
    return path;
  }

  nlohmann::json stats() { return test::parse_json(read_text(dir_.file("stats.json"))); }
  std::string stats_arg() { return " --stats-json " + quoted(dir_.file("stats.json")); }

  TempDir dir_;
};

TEST_F(RtCheckCliTest, CountsEveryAllocatingCycleAndOnlyThose) {
  const auto o = chimera("run " + quoted(two_tasks_file()) + " --clock virtual --for 1s --rt-check" + stats_arg());
  EXPECT_EXIT_CODE(o, 0);
  const auto doc = stats();
  EXPECT_TRUE(doc.at("rt_check").get<bool>());
  const auto& hoarder = doc.at("tasks").at("hoarder");
  const auto cycles = hoarder.at("cycles").get<std::uint64_t>();
  EXPECT_GE(cycles, 99U);
  // Each cycle allocates at least once (the fresh vector); the growing history adds more now and then.
  EXPECT_GE(hoarder.at("rt_violations").get<std::uint64_t>(), cycles);
  EXPECT_GT(doc.at("tasks").at("quiet").at("cycles").get<std::uint64_t>(), 0U);
  EXPECT_EQ(doc.at("tasks").at("quiet").at("rt_violations").get<std::uint64_t>(), 0U);
  // One event for the operator (on stderr, with the other events), however many cycles allocated.
  const auto first = o.err.find(kEvent);
  EXPECT_NE(first, std::string::npos) << o.err;
  EXPECT_EQ(o.err.find(kEvent, first + 1), std::string::npos) << o.err;
  EXPECT_TRUE(contains(o.out, "rt violations")) << o.out;
}

TEST_F(RtCheckCliTest, WithoutTheFlagNothingIsCountedOrShown) {
  const auto o = chimera("run " + quoted(two_tasks_file()) + " --clock virtual --for 1s" + stats_arg());
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_FALSE(contains(o.out, "rt violations")) << o.out;
  EXPECT_FALSE(contains(o.err, "allocated on the real-time path")) << o.err;
  const auto doc = stats();
  EXPECT_FALSE(doc.at("rt_check").get<bool>());
  EXPECT_EQ(doc.at("tasks").at("hoarder").at("rt_violations").get<std::uint64_t>(), 0U);
}

TEST_F(RtCheckCliTest, FigureFourAllocatesNothingOnTheRealTimePath) {
  const auto o = chimera("run " + quoted(fig4_file()) + " --clock virtual --for 1s --rt-check" + stats_arg());
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "rt violations")) << o.out;
  EXPECT_FALSE(contains(o.err, "allocated on the real-time path")) << o.err;
  const auto doc = stats();
  ASSERT_FALSE(doc.at("tasks").empty());
  for (const auto& [name, task] : doc.at("tasks").items()) {
    EXPECT_GT(task.at("cycles").get<std::uint64_t>(), 0U) << name;
    EXPECT_EQ(task.at("rt_violations").get<std::uint64_t>(), 0U) << name;
  }
}

}  // namespace
}  // namespace chimera::test
