// The documents the page is drawn from: the module library (GET /api/modules) and the model
// (GET /api/subsystem), checked on a subsystem of the test modules on the virtual clock.

#include "api_documents.hpp"

#include <unistd.h>

#include <memory>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "unit/control/test_modules.hpp"

namespace chimera::net {
namespace {

using nlohmann::json;

// counter -> doubler in `main`; `spare` counts into a renamed variable and `lonely` reads a
// variable nobody produces, so configuration `broken` is not legal.
constexpr std::string_view kFile = R"(subsystem: documents
tasks:
  - name: counter
    module: test_counter
    period: 1ms
  - name: doubler
    module: test_doubler
    period: 2ms
    criticality: soft
  - name: spare
    module: test_counter
    period: 1ms
    cpu: 0
    rename: { count: spare_count }
  - name: lonely
    module: test_doubler
    period: 1ms
    rename: { count: nobody_writes_this }
configurations:
  main: [counter, doubler]
  broken: [spare, lonely]
start: main
)";

std::unique_ptr<Subsystem> make_subsystem() {
  auto spec = load_subsystem_text(kFile, "documents.yaml", test::test_registry());
  EXPECT_TRUE(spec) << spec.error().message;
  RunOptions options;
  options.clock = ClockKind::kVirtual;
  options.shm_suffix = fmt::format("docs{}", ::getpid());
  auto subsystem = Subsystem::create(*spec, test::test_registry(), options);
  EXPECT_TRUE(subsystem) << subsystem.error().message;
  return std::move(*subsystem);
}

const json* find_named(const json& list, std::string_view key, std::string_view name) {
  for (const auto& item : list)
    if (item.at(key) == name) return &item;
  return nullptr;
}

TEST(ApiDocuments, TheLibraryHasEveryModuleWithItsPortsAndParameters) {
  const json modules = module_library_json(test::test_registry());
  ASSERT_EQ(modules.size(), test::test_registry().list().size());
  const json* doubler = find_named(modules, "name", "test_doubler");
  ASSERT_NE(doubler, nullptr) << modules.dump();
  EXPECT_FALSE((*doubler)["summary"].get<std::string>().empty());
  ASSERT_EQ((*doubler)["ports"].size(), 2U) << doubler->dump();
  EXPECT_EQ((*doubler)["ports"][0],
            (json{{"name", "count"}, {"kind", "in-var"}, {"type", "f64"}, {"size", "1"}, {"doc", "a number"}}));
  EXPECT_EQ((*doubler)["ports"][1]["kind"], "out-var");
  EXPECT_EQ((*doubler)["library"], "");  // linked in, not from a plugin
  for (std::size_t i = 1; i < modules.size(); ++i)
    EXPECT_LT(modules[i - 1]["name"].get<std::string>(), modules[i]["name"].get<std::string>()) << "sorted by name";
}

TEST(ApiDocuments, TheModelBindsPortsAfterRenamesAndVerifiesEveryConfiguration) {
  auto subsystem = make_subsystem();
  ASSERT_NE(subsystem, nullptr);
  const json model = subsystem_model_json(*subsystem);
  EXPECT_EQ(model["subsystem"], "documents");
  EXPECT_EQ(model["configuration"], "main");
  ASSERT_EQ(model["tasks"].size(), 4U);

  const json& spare = *find_named(model["tasks"], "name", "spare");
  EXPECT_EQ(spare["ports"][0]["port"], "count");
  EXPECT_EQ(spare["ports"][0]["variable"], "spare_count");
  EXPECT_EQ(spare["ports"][0]["renamed"], true);
  EXPECT_EQ(spare["ports"][0]["shape"], "f64[1]");
  EXPECT_EQ(spare["rename"], (json{{"count", "spare_count"}}));
  EXPECT_EQ(spare["cpu"], 0);
  EXPECT_EQ(spare["period_ns"], 1'000'000);
  EXPECT_EQ(spare["connector"], "");  // not a join connector (tests/integration/net checks one that is)

  const json& doubler = *find_named(model["tasks"], "name", "doubler");
  EXPECT_EQ(doubler["criticality"], "soft");
  EXPECT_EQ(doubler["cpu"], nullptr);  // not pinned by the file
  EXPECT_EQ(doubler["ports"][0]["variable"], "count");
  EXPECT_EQ(doubler["ports"][0]["renamed"], false);

  const json& main = *find_named(model["configurations"], "name", "main");
  EXPECT_EQ(main["tasks"], (json{"counter", "doubler"}));
  EXPECT_EQ(main["legal"], true);
  EXPECT_EQ(main["violations"], json::array());
  const json& broken = *find_named(model["configurations"], "name", "broken");
  EXPECT_EQ(broken["legal"], false);
  ASSERT_EQ(broken["violations"].size(), 1U) << broken.dump();
  EXPECT_EQ(broken["violations"][0]["rule"], 2);
  EXPECT_EQ(broken["violations"][0]["variable"], "nobody_writes_this");
  EXPECT_EQ(broken["violations"][0]["reason"], "nobody_writes_this has no producer (read by lonely)");
}

TEST(ApiDocuments, TheModelFollowsTheLiveAssembly) {
  auto subsystem = make_subsystem();
  ASSERT_NE(subsystem, nullptr);
  auto added = subsystem->add_task("{name: third, module: test_counter, period: 1ms, rename: {count: doubled}}");
  ASSERT_TRUE(added) << added.error().message;
  auto defined = subsystem->define_configuration("longer", {"counter", "doubler", "third"});
  ASSERT_TRUE(defined) << defined.error().message;
  const json model = subsystem_model_json(*subsystem);
  const json* third = find_named(model["tasks"], "name", "third");
  ASSERT_NE(third, nullptr) << model.dump();
  EXPECT_EQ((*third)["ports"][0]["variable"], "doubled");
  const json& longer = *find_named(model["configurations"], "name", "longer");
  // third writes `doubled` as doubler does: two producers of one variable (equation 1).
  EXPECT_EQ(longer["legal"], false);
  ASSERT_FALSE(longer["violations"].empty());
  EXPECT_EQ(longer["violations"][0]["rule"], 1) << longer.dump();
  EXPECT_EQ(longer["violations"][0]["variable"], "doubled");

  // A task removed is gone from the model, as from status and save.
  auto extra = subsystem->add_task("{name: extra, module: test_counter, period: 1ms, rename: {count: extra_count}}");
  ASSERT_TRUE(extra) << extra.error().message;
  ASSERT_NE(find_named(subsystem_model_json(*subsystem)["tasks"], "name", "extra"), nullptr);
  auto removed = subsystem->remove_task("extra");
  ASSERT_TRUE(removed) << removed.error().message;
  const json after = subsystem_model_json(*subsystem);
  EXPECT_EQ(find_named(after["tasks"], "name", "extra"), nullptr) << after.dump();
  EXPECT_NE(find_named(after["tasks"], "name", "third"), nullptr);
}

}  // namespace
}  // namespace chimera::net
