// From the subsystem file to task models: C from the file, then the profile, then measurements.

#include "chimera/analysis/task_models.hpp"

#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace chimera::analysis {
namespace {

TaskSpec task_spec(const char* name, std::optional<std::int64_t> period, std::int64_t deadline,
                   std::optional<std::int64_t> wcet = std::nullopt) {
  TaskSpec t;
  t.name = name;
  t.period_ns = period;
  t.deadline_ns = deadline;
  t.wcet_ns = wcet;
  return t;
}

SubsystemSpec spec_of_four() {
  SubsystemSpec spec;
  spec.name = "s";
  spec.tasks.push_back(task_spec("filed", 1'000'000, 500'000, 100'000));
  spec.tasks.push_back(task_spec("profiled", 2'000'000, 2'000'000));
  spec.tasks.back().criticality = Criticality::kSoft;
  spec.tasks.push_back(task_spec("measured", 4'000'000, 4'000'000));
  spec.tasks.back().cpu = 1;
  spec.tasks.push_back(task_spec("events", std::nullopt, 0));
  return spec;
}

TEST(TaskModels, CFromTheFileThenTheProfileThenMeasurements) {
  const SubsystemSpec spec = spec_of_four();
  WcetProfile profile;
  profile.tasks.push_back(measured_entry("profiled", 20'000, 1, 1.5));
  profile.tasks.push_back(measured_entry("filed", 1, 1, 1.0));  // the file wins
  WcetProfile measured;
  measured.tasks.push_back(measured_entry("measured", 7'000, 1, 1.0));
  measured.tasks.push_back(measured_entry("profiled", 2, 1, 1.0));  // the profile wins
  const std::vector<std::string> names{"events", "measured", "profiled", "filed"};
  const auto m = task_models(spec, names, &profile, &measured);
  ASSERT_EQ(m.size(), 4U);
  // File order, whatever the order asked.
  EXPECT_EQ(m[0].name, "filed");
  EXPECT_EQ(m[0].wcet_ns, 100'000);
  EXPECT_EQ(m[0].wcet_source, WcetSource::kFile);
  EXPECT_EQ(m[0].deadline_ns, 500'000);
  EXPECT_EQ(m[0].file_index, 0);
  EXPECT_TRUE(m[0].hard);
  EXPECT_EQ(m[1].wcet_ns, 30'000);
  EXPECT_EQ(m[1].wcet_source, WcetSource::kProfile);
  EXPECT_FALSE(m[1].hard);
  EXPECT_EQ(m[2].wcet_ns, 7'000);
  EXPECT_EQ(m[2].wcet_source, WcetSource::kMeasured);
  EXPECT_EQ(m[2].cpu, 1);
  EXPECT_EQ(m[3].period_ns, 0);  // aperiodic: background
  EXPECT_EQ(m[3].wcet_source, WcetSource::kUnknown);
  EXPECT_EQ(m[3].cpu, -1);
  for (const auto& t : m) {
    EXPECT_FALSE(t.server);
    EXPECT_EQ(t.user_priority, 0);
  }
}

TEST(TaskModels, OnlyTheNamedTasksWithoutSources) {
  const SubsystemSpec spec = spec_of_four();
  const std::vector<std::string> names{"measured", "nosuch"};
  const auto m = task_models(spec, names);
  ASSERT_EQ(m.size(), 1U);
  EXPECT_EQ(m[0].name, "measured");
  EXPECT_EQ(m[0].wcet_ns, 0);
  EXPECT_EQ(m[0].wcet_source, WcetSource::kUnknown);
  EXPECT_EQ(m[0].file_index, 2);
}

TEST(TaskModels, PriorityAndServers) {
  SubsystemSpec spec = spec_of_four();
  spec.tasks[0].priority = 7;
  spec.tasks[3].server = ServerSpec{2'000'000, 10'000'000};
  spec.tasks[3].deadline_ns = 10'000'000;  // the loader's default for a served task
  WcetProfile profile;
  profile.tasks.push_back(measured_entry("events", 500'000, 3, 1.0));
  const std::vector<std::string> names{"filed", "events"};
  const auto m = task_models(spec, names, &profile);
  ASSERT_EQ(m.size(), 2U);
  EXPECT_EQ(m[0].user_priority, 7);
  EXPECT_FALSE(m[0].server);
  // The server: its budget per period, and its longest job from the profile.
  EXPECT_TRUE(m[1].server);
  EXPECT_EQ(m[1].wcet_ns, 2'000'000);
  EXPECT_EQ(m[1].job_wcet_ns, 500'000);
  EXPECT_EQ(m[1].wcet_source, WcetSource::kProfile);
  EXPECT_EQ(m[1].period_ns, 10'000'000);
  EXPECT_EQ(m[1].deadline_ns, 10'000'000);
  EXPECT_FALSE(is_background(m[1]));
  const auto d = demand_of(m[1], AnalysisOptions{.overhead_ns = 1'000});
  ASSERT_TRUE(d);
  EXPECT_EQ(d->c_ns, 2'501'000);
  // Without a longest job the server cannot be bounded.
  EXPECT_FALSE(wcet_known(task_models(spec, names)[1]));
}

}  // namespace
}  // namespace chimera::analysis
