// chimera analyze --json as tools script it (contract section 4): stdout is one JSON document and
// nothing else, the exit codes are the text mode's, and the numbers are the text report's for the
// same textbook sets (analyze_cli_test.cpp checks those in the text).

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_chimera.hpp"
#include "support/json_text.hpp"

namespace chimera::test {
namespace {

using Json = nlohmann::json;

const std::string kData = CLI_DATA_DIR;
constexpr std::int64_t kMs = 1'000'000;

std::string data(const std::string& name) { return quoted(kData + "/" + name); }

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

class AnalyzeJsonTest : public ::testing::Test {
 protected:
  Outcome analyze(const std::string& args) { return run_chimera(dir_, "analyze " + args); }
  [[nodiscard]] const TempDir& dir() const { return dir_; }

  // stdout parsed as exactly one document: json::parse fails on anything before or after it.
  static Json parse(const Outcome& o) {
    Json doc = test::parse_json(o.out, /*allow_exceptions=*/false);
    EXPECT_FALSE(doc.is_discarded()) << "stdout is not one JSON document:\n" << o.out;
    return doc;
  }

  // The task called `name` in the document's only configuration, wherever its CPU.
  static Json task(const Json& doc, const std::string& name) {
    for (const auto& cpu : doc.at("configurations").at(0).at("cpus"))
      for (const auto& t : cpu.at("tasks"))
        if (t.at("name") == name) return t;
    ADD_FAILURE() << "no task " << name;
    return {};
  }

 private:
  TempDir dir_;
};

TEST_F(AnalyzeJsonTest, RateMonotonicMissesWhereEdfMeets) {
  auto o = analyze(data("analyze_rm_infeasible.yaml") + " --overhead 0ns --json");
  EXPECT_EXIT_CODE(o, 1);
  EXPECT_TRUE(o.err.empty()) << o.err;
  Json doc = parse(o);
  EXPECT_EQ(doc.at("format"), "chimera-analyze");
  EXPECT_EQ(doc.at("format_version"), 1);
  EXPECT_EQ(doc.at("feasible"), false);
  const Json& rm = doc.at("configurations").at(0);
  EXPECT_EQ(rm.at("name"), "default");
  EXPECT_EQ(rm.at("scheduler"), "rm");
  EXPECT_EQ(rm.at("feasible"), false);
  EXPECT_EQ(rm.at("overhead_ns"), 0);
  EXPECT_EQ(rm.at("can_miss"), Json::array({"slow"}));
  ASSERT_EQ(rm.at("cpus").size(), 1U);
  const Json& cpu = rm.at("cpus").at(0);
  EXPECT_EQ(cpu.at("cpu"), 0);
  EXPECT_NEAR(cpu.at("utilisation").get<double>(), 2.0 / 5 + 4.0 / 7, 1e-9);
  EXPECT_EQ(cpu.at("test"), "response_time");
  EXPECT_NEAR(cpu.at("bound").get<double>(), 2 * (std::sqrt(2.0) - 1), 1e-9);
  EXPECT_EQ(cpu.at("outcome"), "response_time_exceeds_deadline");
  EXPECT_FALSE(cpu.contains("critical_set"));
  // In priority order, as the text lists them: R(fast) = 2 ms, R(slow) = 4 + 2 x 2 = 8 ms > 7 ms.
  ASSERT_EQ(cpu.at("tasks").size(), 2U);
  const Json& fast = cpu.at("tasks").at(0);
  EXPECT_EQ(fast.at("name"), "fast");
  EXPECT_EQ(fast.at("period_ns"), 5 * kMs);
  EXPECT_EQ(fast.at("deadline_ns"), 5 * kMs);
  EXPECT_EQ(fast.at("wcet_ns"), 2 * kMs);
  EXPECT_EQ(fast.at("wcet_source"), "file");
  EXPECT_EQ(fast.at("criticality"), "hard");
  EXPECT_EQ(fast.at("response_ns"), 2 * kMs);
  EXPECT_EQ(fast.at("response_kind"), "exact");
  EXPECT_EQ(fast.at("verdict"), "meets");
  const Json& slow = cpu.at("tasks").at(1);
  EXPECT_EQ(slow.at("name"), "slow");
  EXPECT_EQ(slow.at("response_ns"), 8 * kMs);
  EXPECT_EQ(slow.at("response_kind"), "exact");
  EXPECT_EQ(slow.at("verdict"), "CAN MISS");
  EXPECT_EQ(slow.at("reason"), "response time 8 ms > deadline 7 ms");

  o = analyze(data("analyze_edf_implicit.yaml") + " --overhead 0ns --json");
  EXPECT_EXIT_CODE(o, 0);
  doc = parse(o);
  EXPECT_EQ(doc.at("feasible"), true);
  const Json& edf = doc.at("configurations").at(0);
  EXPECT_EQ(edf.at("scheduler"), "edf");
  EXPECT_EQ(edf.at("can_miss"), Json::array());
  EXPECT_EQ(edf.at("cpus").at(0).at("test"), "edf_utilisation");
  EXPECT_EQ(edf.at("cpus").at(0).at("bound"), 1);
  EXPECT_EQ(edf.at("cpus").at(0).at("outcome"), "feasible");
  EXPECT_EQ(edf.at("cpus").at(0).at("edf").at("utilisation_decides"), true);
  // EDF bounds each response time by the deadline, as the text's "<= 7 ms".
  EXPECT_EQ(task(doc, "slow").at("response_ns"), 7 * kMs);
  EXPECT_EQ(task(doc, "slow").at("response_kind"), "upper_bound");
  EXPECT_EQ(task(doc, "slow").at("verdict"), "meets");
}

TEST_F(AnalyzeJsonTest, TheOverheadIsInTheResponseTimes) {
  // As in the text test: 1 µs per cycle tips c over, R(c) = 10.006 ms > 10 ms.
  const auto o = analyze(data("analyze_rm_above_bound.yaml") + " --json");
  EXPECT_EXIT_CODE(o, 1);
  const Json doc = parse(o);
  EXPECT_EQ(doc.at("configurations").at(0).at("overhead_ns"), 1000);
  EXPECT_EQ(task(doc, "a").at("response_ns"), 1'001'000);
  EXPECT_EQ(task(doc, "b").at("response_ns"), 3'002'000);
  EXPECT_EQ(task(doc, "c").at("response_ns"), 10'006'000);
  EXPECT_EQ(task(doc, "c").at("wcet_ns"), 3 * kMs);          // the file's C
  EXPECT_EQ(task(doc, "c").at("analysed_c_ns"), 3'001'000);  // what the test used
  EXPECT_EQ(task(doc, "c").at("verdict"), "CAN MISS");
}

TEST_F(AnalyzeJsonTest, MufCriticalSets) {
  auto o = analyze(data("analyze_muf.yaml") + " --overhead 0ns --json");
  EXPECT_EXIT_CODE(o, 0);
  Json doc = parse(o);
  Json cpu = doc.at("configurations").at(0).at("cpus").at(0);
  EXPECT_EQ(cpu.at("test"), "muf_critical_set");
  EXPECT_EQ(cpu.at("outcome"), "every_hard_task_fits");
  EXPECT_EQ(cpu.at("critical_set"), Json::array({"a", "b"}));
  EXPECT_EQ(cpu.at("unfit_hard"), Json::array());
  EXPECT_NEAR(cpu.at("edf").at("utilisation").get<double>(), 0.8, 1e-9);
  EXPECT_EQ(task(doc, "b").at("critical"), true);
  EXPECT_EQ(task(doc, "b").at("response_ns"), 10 * kMs);
  EXPECT_EQ(task(doc, "b").at("response_kind"), "upper_bound");
  EXPECT_EQ(task(doc, "b").at("verdict"), "meets");
  EXPECT_EQ(task(doc, "c").at("criticality"), "soft");
  EXPECT_EQ(task(doc, "c").at("critical"), false);
  EXPECT_EQ(task(doc, "c").at("verdict"), "no guarantee");
  EXPECT_EQ(task(doc, "c").at("response_ns"), nullptr);
  EXPECT_EQ(task(doc, "c").at("response_kind"), "none");
  EXPECT_EQ(task(doc, "d").at("verdict"), "no guarantee");

  // y (shorter period) is admitted first; x does not fit and is not in the set.
  o = analyze(data("analyze_muf_unfit.yaml") + " --overhead 0ns --json");
  EXPECT_EXIT_CODE(o, 1);
  doc = parse(o);
  cpu = doc.at("configurations").at(0).at("cpus").at(0);
  EXPECT_EQ(cpu.at("feasible"), false);
  EXPECT_EQ(cpu.at("outcome"), "a_hard_task_does_not_fit");
  EXPECT_EQ(cpu.at("critical_set"), Json::array({"y"}));
  EXPECT_EQ(cpu.at("unfit_hard"), Json::array({"x"}));
  EXPECT_EQ(doc.at("configurations").at(0).at("can_miss"), Json::array({"x"}));
  EXPECT_EQ(task(doc, "x").at("verdict"), "CAN MISS");
  EXPECT_EQ(task(doc, "x").at("reason"),
            "hard, but does not fit in the critical set: with it, overloaded: U = 1.100 > 1");
}

TEST_F(AnalyzeJsonTest, EveryCpuAndEveryTaskPlaced) {
  const auto o = analyze(data("analyze_two_cpus.yaml") + " --overhead 0ns --json");
  EXPECT_EXIT_CODE(o, 0);
  const Json doc = parse(o);
  const Json& cpus = doc.at("configurations").at(0).at("cpus");
  ASSERT_EQ(cpus.size(), 2U);
  EXPECT_EQ(cpus.at(1).at("cpu"), 1);
  EXPECT_EQ(task(doc, "big").at("cpu"), 0);
  EXPECT_EQ(task(doc, "small").at("cpu"), 0);
  EXPECT_EQ(task(doc, "medium").at("cpu"), 1);
  EXPECT_EQ(task(doc, "pinned").at("cpu"), 1);
  EXPECT_EQ(task(doc, "pinned").at("placed"), "pinned");
  EXPECT_EQ(task(doc, "medium").at("placed"), "assigned");
}

TEST_F(AnalyzeJsonTest, ServersAndBackgroundTasks) {
  const auto o = analyze(data("analyze_server.yaml") + " --overhead 0ns --json");
  EXPECT_EXIT_CODE(o, 0);
  const Json doc = parse(o);
  EXPECT_EQ(task(doc, "cmd").at("server"), true);
  EXPECT_EQ(task(doc, "cmd").at("wcet_ns"), 2 * kMs);
  EXPECT_EQ(task(doc, "cmd").at("job_wcet_ns"), 1 * kMs);
  EXPECT_EQ(task(doc, "cmd").at("response_ns"), 8 * kMs);
  EXPECT_EQ(task(doc, "log").at("verdict"), "background");
  EXPECT_EQ(task(doc, "log").at("period_ns"), nullptr);
  EXPECT_EQ(task(doc, "log").at("deadline_ns"), nullptr);
}

TEST_F(AnalyzeJsonTest, OneDocumentForAllConfigurations) {
  auto o = analyze(data("analyze_two_configs.yaml") + " --overhead 0ns --json");
  EXPECT_EXIT_CODE(o, 1);
  Json doc = parse(o);
  ASSERT_EQ(doc.at("configurations").size(), 2U);
  EXPECT_EQ(doc.at("configurations").at(0).at("name"), "light");
  EXPECT_EQ(doc.at("configurations").at(0).at("feasible"), true);
  EXPECT_EQ(doc.at("configurations").at(1).at("name"), "heavy");
  EXPECT_EQ(doc.at("configurations").at(1).at("can_miss"), Json::array({"slow"}));
  EXPECT_EQ(doc.at("feasible"), false);

  o = analyze(data("analyze_two_configs.yaml") + " --overhead 0ns --config light --json");
  EXPECT_EXIT_CODE(o, 0);
  doc = parse(o);
  ASSERT_EQ(doc.at("configurations").size(), 1U);
  EXPECT_EQ(doc.at("feasible"), true);
}

TEST_F(AnalyzeJsonTest, ExitCodesAreTheTextModes) {
  for (const char* file : {"analyze_rm_above_bound.yaml", "analyze_rm_infeasible.yaml", "analyze_edf_constrained.yaml",
                           "analyze_edf_constrained_miss.yaml", "analyze_dm.yaml", "analyze_muf.yaml",
                           "analyze_muf_unfit.yaml", "analyze_two_configs.yaml", "bad_period.yaml", "illegal.yaml"}) {
    const auto text = analyze(data(file) + " --overhead 0ns");
    const auto json = analyze(data(file) + " --overhead 0ns --json");
    EXPECT_EQ(json.exit_code, text.exit_code) << file;
    if (text.exit_code != 2) {
      const Json doc = parse(json);
      EXPECT_EQ(doc.at("feasible"), text.exit_code == 0) << file;
    }
  }
}

TEST_F(AnalyzeJsonTest, InvalidInputPrintsNoDocument) {
  // Diagnostics stay on stderr; a tool sees empty stdout and exit 2, never half a document.
  auto o = analyze(data("bad_period.yaml") + " --json");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_EQ(o.out, "");
  EXPECT_NE(o.err.find("bad_period.yaml:8: tasks[1].period"), std::string::npos) << o.err;

  o = analyze(data("illegal.yaml") + " --json");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_EQ(o.out, "");
  EXPECT_NE(o.err.find("only legal configurations can be analysed"), std::string::npos) << o.err;
}

TEST_F(AnalyzeJsonTest, ProfileBudgetsSayWhereTheyCameFrom) {
  const std::string profile = quoted(dir().file("wcet.yaml"));
  write_text(dir().file("wcet.yaml"),
             "subsystem: an_measured\ntasks:\n  slow: { wcet: 300ms }\n  slower: { wcet: 900ms }\n");
  const auto o = analyze(data("analyze_measured.yaml") + " --overhead 0ns --wcet-from " + profile + " --json");
  EXPECT_EXIT_CODE(o, 0);
  const Json doc = parse(o);
  EXPECT_EQ(doc.at("configurations").at(0).at("measured"), nullptr);
  EXPECT_EQ(task(doc, "slow").at("wcet_source"), "profile");
  EXPECT_EQ(task(doc, "slow").at("wcet_ns"), 300 * kMs);
  EXPECT_EQ(task(doc, "slower").at("response_ns"), 1500 * kMs);
}

}  // namespace
}  // namespace chimera::test
