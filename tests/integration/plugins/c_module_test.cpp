// A module written in C (include/chimera/module/c_module.h), loaded from a library and run on
// the virtual clock: its ports, parameters, timing and freshness, and the lifecycle's error paths
// taken from the reasons its methods return.

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/plugin_loader.hpp"
#include "support/probe_module.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

class CModuleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto loaded = load_plugin("c_counter", PLUGIN_GOOD_DIR "/libchimera_test_c_counter.so");
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  }

  // A subsystem of one counter task with these params, created (not started) on the virtual clock.
  static std::unique_ptr<Subsystem> counter(const std::string& params) {
    const std::string text =
        "subsystem: c_counter\nconstants: { u: [5] }\ntasks:\n"
        "  - { name: counter, module: test_c_counter, period: 10ms, params: " +
        params + " }\n";
    auto spec = load_subsystem_text(text, "c.yaml", Registry::global());
    EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
    if (!spec.ok()) return nullptr;
    specs_.push_back(std::make_unique<SubsystemSpec>(*std::move(spec)));
    RunOptions o;
    o.clock = ClockKind::kVirtual;
    o.shm_suffix = testing::unique_suffix();
    auto s = Subsystem::create(*specs_.back(), Registry::global(), o);
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    return s.ok() ? std::move(*s) : nullptr;
  }

  static double value(const Subsystem& s, const std::string& variable, std::size_t i = 0) {
    auto v = s.get(variable);
    EXPECT_TRUE(v.ok()) << variable;
    return v.ok() && i < v->size() ? (*v)[i] : -1.0;
  }

  static inline std::vector<std::unique_ptr<SubsystemSpec>> specs_;
};

TEST_F(CModuleTest, ItsParameterRulesAreCheckedByTheLoader) {
  const auto head =
      std::string("subsystem: c\ntasks:\n  - name: k\n    module: test_c_counter\n    period: 1ms\n    params:\n");
  auto narrow = load_subsystem_text(head + "      width: 2\n", "c.yaml", Registry::global());
  ASSERT_FALSE(narrow.ok());
  EXPECT_EQ(narrow.error().message, "c.yaml:7: tasks[0].params.width: 2 given: must be whole, >= 3");
  auto label = load_subsystem_text(head + "      label: x\n", "c.yaml", Registry::global());
  ASSERT_FALSE(label.ok());
  EXPECT_EQ(label.error().message,
            "c.yaml:7: tasks[0].params.label: \"x\" given: must be one of: counter, other, refuse");
  auto half = load_subsystem_text(head + "      width: 3.5\n", "c.yaml", Registry::global());
  ASSERT_FALSE(half.ok());
  EXPECT_EQ(half.error().message, "c.yaml:7: tasks[0].params.width: 3.5 given: must be whole, >= 3");
  EXPECT_TRUE(load_subsystem_text(head + "      width: 4\n      label: other\n", "c.yaml", Registry::global()).ok());
}

TEST_F(CModuleTest, RunsItsMethodsThroughTheFramework) {
  auto s = counter("{ offset: 100 }");
  ASSERT_NE(s, nullptr);
  ASSERT_TRUE(s->start().ok());
  s->run_for(95 * kMs);  // releases at 0, 10, ..., 90 ms
  EXPECT_EQ(value(*s, "count"), 110.0) << "on() set the offset, each of 10 cycles added one";
  EXPECT_EQ(value(*s, "seen", 0), 1.0) << "u, a constant, is old after its first transfer (CHIMERA_OLD)";
  EXPECT_DOUBLE_EQ(value(*s, "seen", 1), 0.09) << "release time of the last cycle";
  EXPECT_DOUBLE_EQ(value(*s, "seen", 2), 0.01) << "the period";
  EXPECT_EQ(s->snapshot()[0].state, TaskState::kOn);
}

TEST_F(CModuleTest, PortsDependOnParameters) {
  auto s = counter("{ width: 5 }");
  ASSERT_NE(s, nullptr);
  ASSERT_TRUE(s->start().ok());
  auto seen = s->get("seen");
  ASSERT_TRUE(seen.ok());
  EXPECT_EQ(seen->size(), 5u);
}

TEST_F(CModuleTest, AnInitFailureCarriesItsReason) {
  auto s = counter("{ label: refuse }");
  ASSERT_NE(s, nullptr);
  auto started = s->start();
  ASSERT_FALSE(started.ok());
  // chimera_refuse named the parameter: the message points at the line that gives it.
  EXPECT_EQ(started.error().message, "c.yaml:4: counter.params.label: init failed: label says refuse");
  EXPECT_EQ(s->snapshot()[0].state, TaskState::kNotCreated);
}

TEST_F(CModuleTest, ACycleFailureSendsTheTaskToErrorUnlessErrorRecovers) {
  auto failing = counter("{ fail_at: 3 }");
  ASSERT_NE(failing, nullptr);
  ASSERT_TRUE(failing->start().ok());
  failing->run_for(95 * kMs);
  const auto snapshot = failing->snapshot()[0];
  EXPECT_EQ(snapshot.state, TaskState::kError);
  EXPECT_NE(snapshot.last_error.find("counter failed on purpose"), std::string::npos) << snapshot.last_error;
  EXPECT_EQ(value(*failing, "count"), 3.0) << "no cycle after the failure";

  auto recovering = counter("{ fail_at: 3, recover: true }");
  ASSERT_NE(recovering, nullptr);
  ASSERT_TRUE(recovering->start().ok());
  recovering->run_for(95 * kMs);
  EXPECT_EQ(recovering->snapshot()[0].state, TaskState::kOn);
  EXPECT_EQ(value(*recovering, "count"), 10.0);
}

TEST_F(CModuleTest, DeclarationsAndDocumentationReachTheRegistry) {
  const ModuleInfo* info = Registry::global().find("test_c_counter");
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->summary, "counts cycles (test plugin in C)");
  const Declarations d = info->declarations(Params{});
  ASSERT_EQ(d.ports().size(), 3u);
  EXPECT_EQ(d.ports()[0].kind, PortKind::kInVar);
  EXPECT_EQ(d.ports()[2].dim.factor, 3u);
  ASSERT_EQ(d.params().size(), 6u);
  EXPECT_EQ(d.params()[3].type, ParamType::kBool);
  EXPECT_EQ(d.params()[4].type, ParamType::kString);
  EXPECT_EQ(std::get<Vector>(d.params()[5].default_value), (Vector{1.0, 2.0}));
  EXPECT_EQ(d.resource(), "nothing (a test)");
}

}  // namespace
}  // namespace chimera
