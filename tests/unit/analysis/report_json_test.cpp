// analysis_json() on results built by hand, so that every field is seen to come from the struct
// it names (the CLI test checks the same fields on results the analysis computed).

#include "chimera/analysis/report_json.hpp"

#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/json_text.hpp"

namespace chimera::analysis {
namespace {

using Json = nlohmann::json;
constexpr std::int64_t kMs = 1'000'000;

TaskModel model(const char* name, std::int64_t c, std::int64_t t, int file_index, bool hard = true) {
  return TaskModel{.name = name,
                   .wcet_ns = c,
                   .period_ns = t,
                   .hard = hard,
                   .file_index = file_index,
                   .wcet_source = WcetSource::kFile};
}

TaskResult result(std::size_t index, Verdict verdict, std::int64_t response_ns, std::string reason = {}) {
  TaskResult r;
  r.index = index;
  r.verdict = verdict;
  r.response_ns = response_ns;
  r.reason = std::move(reason);
  return r;
}

// Two CPUs under rm: on 0, "fast" meets and "slow" misses with a lower bound; 1 is empty.
AnalysedConfiguration rm_configuration() {
  AnalysedConfiguration c;
  c.context = ReportContext{"f.yaml", "main", SchedulerKind::kRm, AnalysisOptions{.overhead_ns = 0}, "measured: how"};
  c.tasks = {model("slow", 4 * kMs, 7 * kMs, 0), model("fast", 2 * kMs, 5 * kMs, 1)};
  c.tasks[0].wcet_source = WcetSource::kProfile;
  c.tasks[1].cpu = 0;
  CpuResult cpu0;
  cpu0.cpu = 0;
  cpu0.periodic = 2;
  cpu0.utilisation = 0.97;
  cpu0.ll_bound = 0.83;
  cpu0.test = CpuTest::kResponseTime;
  cpu0.feasible = false;
  cpu0.tasks.push_back(result(1, Verdict::kMeets, 2 * kMs));
  cpu0.tasks.back().demand = Demand{2 * kMs, 5 * kMs, 5 * kMs};
  cpu0.tasks.push_back(result(0, Verdict::kCanMiss, 9 * kMs, "response time at least 9 ms > deadline 7 ms"));
  cpu0.tasks.back().response_is_lower_bound = true;
  CpuResult cpu1;
  cpu1.cpu = 1;
  c.result.cpu_of = {0, 0};
  c.result.cpus = {cpu0, cpu1};
  c.result.feasible = false;
  return c;
}

// One CPU under muf: a fits, h is hard and does not (so it is outside the set), s is outside it too.
AnalysedConfiguration muf_configuration() {
  AnalysedConfiguration c;
  c.context = ReportContext{"f.yaml", "other", SchedulerKind::kMuf, AnalysisOptions{}, ""};
  c.tasks = {model("a", 2 * kMs, 4 * kMs, 0), model("h", 3 * kMs, 5 * kMs, 1), model("s", kMs, 8 * kMs, 2, false)};
  CpuResult cpu;
  cpu.cpu = 0;
  cpu.periodic = 3;
  cpu.test = CpuTest::kMufCriticalSet;
  cpu.edf.outcome = EdfOutcome::kFeasible;
  cpu.edf.utilisation = 0.5;
  cpu.edf.utilisation_decides = true;
  cpu.feasible = false;
  cpu.hard_left_out = true;
  cpu.tasks.push_back(result(0, Verdict::kMeets, 4 * kMs));
  cpu.tasks.back().critical = true;
  cpu.tasks.back().response_is_bound = true;
  cpu.tasks.push_back(result(1, Verdict::kCanMiss, 0, "hard, but does not fit"));  // not critical: left out
  cpu.tasks.push_back(result(2, Verdict::kNoGuarantee, 0, "outside the critical set"));
  c.result.cpu_of = {0, 0, 0};
  c.result.cpus = {cpu};
  c.result.feasible = false;
  return c;
}

TEST(ReportJson, FieldsComeFromTheResults) {
  const std::vector<AnalysedConfiguration> configurations{rm_configuration(), muf_configuration()};
  const std::string text = analysis_json("f.yaml", configurations);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  const Json doc = test::parse_json(text);
  EXPECT_EQ(doc.at("format"), "chimera-analyze");
  EXPECT_EQ(doc.at("format_version"), kAnalysisJsonFormatVersion);
  EXPECT_EQ(doc.at("file"), "f.yaml");
  EXPECT_EQ(doc.at("feasible"), false);
  ASSERT_EQ(doc.at("configurations").size(), 2U);

  const Json& rm = doc.at("configurations").at(0);
  EXPECT_EQ(rm.at("name"), "main");
  EXPECT_EQ(rm.at("scheduler"), "rm");
  EXPECT_EQ(rm.at("measured"), "measured: how");
  EXPECT_EQ(rm.at("can_miss"), Json::array({"slow"}));
  ASSERT_EQ(rm.at("cpus").size(), 2U);
  const Json& cpu0 = rm.at("cpus").at(0);
  EXPECT_EQ(cpu0.at("test"), "response_time");
  EXPECT_DOUBLE_EQ(cpu0.at("bound").get<double>(), 0.83);
  EXPECT_DOUBLE_EQ(cpu0.at("utilisation").get<double>(), 0.97);
  EXPECT_EQ(cpu0.at("outcome"), "response_time_exceeds_deadline");
  EXPECT_FALSE(cpu0.contains("edf"));
  const Json& fast = cpu0.at("tasks").at(0);  // the results' order, not the file's
  EXPECT_EQ(fast, test::parse_json(R"({"name": "fast", "cpu": 0, "placed": "pinned", "criticality": "hard",
      "period_ns": 5000000, "deadline_ns": 5000000, "wcet_ns": 2000000, "wcet_source": "file",
      "analysed_c_ns": 2000000, "response_ns": 2000000, "response_kind": "exact", "release_jitter_ns": 0,
      "verdict": "meets", "reason": ""})"));
  const Json& slow = cpu0.at("tasks").at(1);
  EXPECT_EQ(slow.at("placed"), "assigned");
  EXPECT_EQ(slow.at("wcet_source"), "profile");
  EXPECT_EQ(slow.at("analysed_c_ns"), nullptr);
  EXPECT_EQ(slow.at("response_ns"), 9 * kMs);
  EXPECT_EQ(slow.at("response_kind"), "lower_bound");
  EXPECT_EQ(slow.at("verdict"), "CAN MISS");
  EXPECT_EQ(slow.at("reason"), "response time at least 9 ms > deadline 7 ms");
  const Json& cpu1 = rm.at("cpus").at(1);
  EXPECT_EQ(cpu1.at("test"), "none");
  EXPECT_EQ(cpu1.at("bound"), nullptr);
  EXPECT_EQ(cpu1.at("tasks"), Json::array());

  const Json& muf = doc.at("configurations").at(1);
  EXPECT_EQ(muf.at("overhead_ns"), kDefaultOverheadNs);
  EXPECT_EQ(muf.at("measured"), nullptr);
  const Json& cpu = muf.at("cpus").at(0);
  EXPECT_EQ(cpu.at("bound"), 1);
  EXPECT_EQ(cpu.at("outcome"), "a_hard_task_does_not_fit");
  EXPECT_EQ(cpu.at("critical_set"), Json::array({"a"}));
  EXPECT_EQ(cpu.at("unfit_hard"), Json::array({"h"}));
  EXPECT_EQ(cpu.at("edf").at("outcome"), "feasible");
  EXPECT_EQ(cpu.at("tasks").at(0).at("response_kind"), "upper_bound");
  EXPECT_EQ(cpu.at("tasks").at(0).at("critical"), true);
  EXPECT_EQ(cpu.at("tasks").at(2).at("criticality"), "soft");
  EXPECT_EQ(cpu.at("tasks").at(2).at("critical"), false);
  EXPECT_EQ(cpu.at("tasks").at(2).at("response_ns"), nullptr);
  EXPECT_EQ(cpu.at("tasks").at(2).at("verdict"), "no guarantee");
}

TEST(ReportJson, AFeasibleFileAndNoConfigurations) {
  EXPECT_EQ(test::parse_json(analysis_json("f.yaml", {})).at("feasible"), true);
  AnalysedConfiguration c = muf_configuration();
  c.result.feasible = true;
  EXPECT_EQ(test::parse_json(analysis_json("f.yaml", std::vector{c})).at("feasible"), true);
}

TEST(ReportJson, AnEdfDemandFailureCarriesItsInterval) {
  AnalysedConfiguration c;
  c.context = ReportContext{"f.yaml", "main", SchedulerKind::kEdf, AnalysisOptions{}, ""};
  c.tasks = {model("a", 2 * kMs, 6 * kMs, 0)};
  CpuResult cpu;
  cpu.cpu = 0;
  cpu.periodic = 1;
  cpu.test = CpuTest::kEdfProcessorDemand;
  cpu.edf = EdfTest{.outcome = EdfOutcome::kDemandExceeded,
                    .utilisation = 0.9,
                    .bound_ns = 16 * kMs,
                    .points = 5,
                    .interval_ns = 6 * kMs,
                    .demand_ns = 7 * kMs};
  cpu.feasible = false;
  cpu.tasks.push_back(result(0, Verdict::kCanMiss, 0, "the jobs due in the first 6 ms need 7 ms"));
  c.result.cpu_of = {0};
  c.result.cpus = {cpu};
  c.result.feasible = false;
  const Json edf =
      test::parse_json(analysis_json("f.yaml", std::vector{c})).at("configurations").at(0).at("cpus").at(0);
  EXPECT_EQ(edf.at("outcome"), "demand_exceeded");
  EXPECT_EQ(edf.at("edf"), test::parse_json(R"({"outcome": "demand_exceeded", "utilisation": 0.9,
      "utilisation_decides": false, "demand_bound_ns": 16000000, "points": 5, "interval_ns": 6000000,
      "demand_ns": 7000000})"));
}

}  // namespace
}  // namespace chimera::analysis
