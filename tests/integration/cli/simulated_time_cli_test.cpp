// On the virtual clock an execution time is simulated time (issue 12, item 5): `chimera analyze`
// takes each task's C from a virtual-clock run as its simulated time (virtual_exec plus what
// cpu_load charged), not the host's microseconds, and its verdict is what a virtual-clock run of
// the same file does; the run's statistics say which clock their execution times are in.

#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_chimera.hpp"
#include "support/json_text.hpp"

namespace chimera::test {
namespace {

using Json = nlohmann::json;

const std::string kData = CLI_DATA_DIR;
constexpr std::int64_t kMs = 1'000'000;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

class SimulatedTimeTest : public ::testing::Test {
 protected:
  Outcome chimera(const std::string& args) { return run_chimera(dir_, args); }
  [[nodiscard]] std::string path(const std::string& name) const { return dir_.file(name); }
  static std::string data(const std::string& name) { return quoted(kData + "/" + name); }

  static Json task(const Json& analysis, const std::string& name) {
    for (const auto& t : analysis.at("configurations").at(0).at("cpus").at(0).at("tasks"))
      if (t.at("name") == name) return t;
    ADD_FAILURE() << "no task " << name;
    return {};
  }

  // A virtual-clock run of `file` for `for_spec`; its --stats-json document.
  Json run_virtual(const std::string& file, const std::string& for_spec) {
    const std::string json = path("stats.json");
    const auto o =
        chimera("run " + data(file) + " --clock virtual --for " + for_spec + " --stats-json " + quoted(json));
    EXPECT_TRUE(o.exit_code == 0 || o.exit_code == 1) << o.err;
    return test::parse_json(read_text(json));
  }

 private:
  TempDir dir_;
};

TEST_F(SimulatedTimeTest, AnalyzeTakesTheSimulatedTimeAndTheRunAgrees) {
  const auto o = chimera("analyze " + data("analyze_muf_simulated.yaml") + " --json");
  EXPECT_EXIT_CODE(o, 0);
  const Json doc = test::parse_json(o.out);
  // The C the virtual clock charges, exactly: 2 ms from cpu_load, 3 ms from virtual_exec.
  EXPECT_EQ(task(doc, "a").at("wcet_ns"), 2 * kMs);
  EXPECT_EQ(task(doc, "a").at("wcet_source"), "simulated");
  EXPECT_EQ(task(doc, "b").at("wcet_ns"), 3 * kMs);
  EXPECT_EQ(task(doc, "b").at("wcet_source"), "virtual_exec");
  EXPECT_EQ(task(doc, "c").at("wcet_ns"), 2 * kMs);
  // a's C is not known before a run, so the run admits no soft task: c is outside the set.
  const Json cpu = doc.at("configurations").at(0).at("cpus").at(0);
  EXPECT_EQ(cpu.at("critical_set"), Json::array({"a", "b"}));
  EXPECT_EQ(task(doc, "a").at("verdict"), "meets");
  EXPECT_EQ(task(doc, "b").at("verdict"), "meets");
  EXPECT_EQ(task(doc, "c").at("verdict"), "no guarantee");

  const Json stats = run_virtual("analyze_muf_simulated.yaml", "1s");
  EXPECT_EQ(stats.at("exec_clock"), "virtual");
  const Json& a = stats.at("tasks").at("a");
  EXPECT_EQ(a.at("exec_clock"), "virtual");
  EXPECT_EQ(a.at("exec_ns").at("max"), 2 * kMs);  // simulated, not the host's microseconds
  EXPECT_TRUE(a.at("host_exec_ns").at("max").is_number());
  EXPECT_EQ(stats.at("tasks").at("b").at("exec_ns").at("max"), 3 * kMs);
  EXPECT_EQ(a.at("missed"), 0);
  EXPECT_EQ(stats.at("tasks").at("b").at("missed"), 0);
  EXPECT_GT(stats.at("tasks").at("c").at("missed").get<int>(), 0);  // 1.2 of the CPU: the soft one gives

  // The text says where C came from and how.
  const auto text = chimera("analyze " + data("analyze_muf_simulated.yaml"));
  EXPECT_TRUE(contains(text.out,
                       "measured: C = the longest cycle's simulated time (virtual_exec plus what the module "
                       "charged), the least of 5 runs of"))
      << text.out;
  EXPECT_TRUE(contains(text.out, "critical set a, b: ")) << text.out;
}

TEST_F(SimulatedTimeTest, AnOverloadInSimulatedTimeIsNotFeasible) {
  const auto o = chimera("analyze " + data("analyze_muf_simulated_overload.yaml") + " --json");
  EXPECT_EXIT_CODE(o, 1);
  const Json doc = test::parse_json(o.out);
  EXPECT_EQ(task(doc, "x").at("wcet_ns"), 3 * kMs);
  EXPECT_EQ(task(doc, "y").at("wcet_ns"), 3 * kMs);
  // Neither C is known before the run, so both are critical, and the set fails EDF's test.
  const Json cpu = doc.at("configurations").at(0).at("cpus").at(0);
  EXPECT_EQ(cpu.at("critical_set"), Json::array({"y", "x"}));
  EXPECT_EQ(cpu.at("outcome"), "critical_set_not_guaranteed");
  EXPECT_EQ(task(doc, "x").at("verdict"), "CAN MISS");
  EXPECT_EQ(task(doc, "y").at("verdict"), "CAN MISS");

  const Json stats = run_virtual("analyze_muf_simulated_overload.yaml", "300ms");
  EXPECT_GT(stats.at("tasks").at("x").at("missed").get<int>() + stats.at("tasks").at("y").at("missed").get<int>(), 0);
}

TEST_F(SimulatedTimeTest, TheTimingTableAndStatsSayTheClock) {
  const auto o = chimera("run " + data("analyze_muf_simulated.yaml") + " --clock virtual --for 100ms");
  EXPECT_TRUE(contains(o.out, "exec mean (simulated)")) << o.out;
  EXPECT_TRUE(contains(o.out, "exec max (simulated)")) << o.out;
}

TEST_F(SimulatedTimeTest, ProfileOnTheVirtualClockWritesSimulatedTime) {
  const std::string out = path("wcet.yaml");
  const auto p = chimera("profile " + data("analyze_muf_simulated.yaml") +
                         " --for 200ms --clock virtual --margin 1.5 -o " + quoted(out));
  EXPECT_EXIT_CODE(p, 0);
  const std::string text = read_text(out);
  EXPECT_TRUE(contains(text, "  a: { wcet: 3ms, exec_max: 2ms")) << text;  // 2 ms x 1.5
  EXPECT_TRUE(contains(text, "  b: { wcet: 4.5ms, exec_max: 3ms")) << text;
  EXPECT_TRUE(contains(p.out, "simulated time")) << p.out;
}

}  // namespace
}  // namespace chimera::test
