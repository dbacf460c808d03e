// GET /api/status as the page and scripts read it, through the API in-process on the virtual
// clock: the imports the bridge reports (docs/dds.md) are in it beside the tasks, as the shell's
// `status` shows them, and an empty list for a subsystem that imports nothing.

#include <unistd.h>

#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/net/access_tokens.hpp"
#include "chimera/net/control_api.hpp"
#include "chimera/net/control_gate.hpp"
#include "support/json_text.hpp"
#include "unit/control/test_modules.hpp"

namespace chimera::net {
namespace {

using nlohmann::json;

constexpr std::string_view kFile = R"(subsystem: status_doc
tasks:
  - {name: counter, module: test_counter, period: 1ms}
configurations:
  main: [counter]
start: main
)";
const std::string kViewer = "viewer-token-0123456789abcdef";

TEST(StatusDocument, ListsTheImportsTheBridgeReports) {
  auto spec = load_subsystem_text(kFile, "status_doc.yaml", test::test_registry());
  ASSERT_TRUE(spec) << spec.error().message;
  RunOptions options;
  options.clock = ClockKind::kVirtual;
  options.shm_suffix = fmt::format(".status_doc.{}", ::getpid());
  auto subsystem = Subsystem::create(*spec, test::test_registry(), options);
  ASSERT_TRUE(subsystem) << subsystem.error().message;
  ASSERT_TRUE((*subsystem)->start());
  auto tokens = AccessTokens::parse("operator operator-token-0123456789ab\nviewer " + kViewer + "\n", "test");
  ASSERT_TRUE(tokens) << tokens.error().message;
  {
    ControlGate gate(**subsystem);
    ControlApi api(gate, std::move(*tokens));
    const std::string bearer = "Bearer " + kViewer;
    auto status = [&] {
      const ApiResponse r = api.handle(ApiRequest{"GET", "/api/status", bearer, "", false});
      EXPECT_EQ(r.status, 200) << r.body;
      return test::parse_json(r.body)["status"];
    };
    EXPECT_EQ(status()["imports"], json::array());

    (*subsystem)->report_remote_imports([] {
      return std::vector<RemoteImport>{
          RemoteImport{"x_d", "vision", 120, 0, 2'000'000, 50'000'000, false, ""},
          RemoteImport{"x_m", "", 0, 3, -1, 50'000'000, true, "import x_m: a remote of another size"}};
    });
    const json imports = status()["imports"];
    ASSERT_EQ(imports.size(), 2U) << imports.dump();
    EXPECT_EQ(imports[0], (json{{"variable", "x_d"},
                                {"stale", false},
                                {"writer", "vision"},
                                {"samples", 120},
                                {"refused", 0},
                                {"age_ns", 2'000'000},
                                {"max_age_ns", 50'000'000},
                                {"refusal", ""}}));
    EXPECT_EQ(imports[1]["stale"], true);
    EXPECT_EQ(imports[1]["age_ns"], -1);
    EXPECT_EQ(imports[1]["refused"], 3);
    EXPECT_EQ(imports[1]["refusal"], "import x_m: a remote of another size");
    (*subsystem)->report_remote_imports({});
  }
  (*subsystem)->stop();
}

}  // namespace
}  // namespace chimera::net
