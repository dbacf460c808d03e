// Opening subsystem files over the network control API (docs/control-api.md, "Open"): every
// example of the tree, as GET /api/examples gives it, opens in a running `chimera run --listen`
// and runs; a file that cannot run is refused with the loader's file, line and key and changes
// nothing; the server's files stay the server's.

#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "chimera_process.hpp"
#include "http_client.hpp"
#include "run_chimera.hpp"
#include "support/json_text.hpp"

namespace chimera::test {
namespace {

using nlohmann::json;

const std::string kOperator = "operator-token-open-0123456789";
const std::string kViewer = "viewer-token-open-0123456789";

json body_of(const HttpResponse& r) {
  json doc = test::parse_json(r.body, false);
  return doc.is_discarded() ? json{{"unparsed", r.body}} : doc;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string unique_name() {
  static int made = 0;
  return "open_" + std::to_string(::getpid()) + "_" + std::to_string(made++);
}

// `text` with its top-level `subsystem:` named `name`.
std::string renamed(const std::string& text, const std::string& name) {
  std::istringstream lines(text);
  std::string out;
  for (std::string line; std::getline(lines, line);)
    out += (line.rfind("subsystem:", 0) == 0 ? "subsystem: " + name : line) + "\n";
  return out;
}

class OpenApiTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { std::signal(SIGPIPE, SIG_IGN); }

  // `chimera run` of the API tests' Figure 4 on the virtual clock, its temporary files in the
  // test's folder (TMPDIR), so that the test sees what open leaves there.
  std::unique_ptr<ChimeraProcess> start(const std::string& clock = "virtual") {
    const std::string tokens = dir_.file("tokens");
    write_text(tokens, "operator " + kOperator + "\nviewer " + kViewer + "\n");
    ::chmod(tokens.c_str(), 0600);
    std::filesystem::create_directories(dir_.file("tmp"));
    auto p = std::make_unique<ChimeraProcess>(
        dir_,
        std::vector<std::string>{"run", private_copy(dir_, "net_fig4.yaml"), "--clock", clock, "--listen",
                                 "127.0.0.1:0", "--token-file", tokens},
        std::vector<std::string>{"TMPDIR=" + dir_.file("tmp")});
    port_ = p->port();
    return p;
  }

  HttpResponse open(const std::string& file, const std::string& text, const std::string& token = kOperator) const {
    HttpRequest r{"POST", "/api/open", token};
    r.body = json{{"file", file}, {"text", text}}.dump();
    return http(port_, r);
  }
  HttpResponse open_body(const std::string& body) const {
    HttpRequest r{"POST", "/api/open", kOperator};
    r.body = body;
    return http(port_, r);
  }
  json status() const { return body_of(http(port_, HttpRequest{"GET", "/api/status", kViewer}))["status"]; }
  HttpResponse run(const std::string& line) const { return command(port_, kOperator, line); }

  TempDir dir_;
  int port_ = 0;
};

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_REPLY(response, code) EXPECT_EQ((response).status, code) << (response).body

TEST_F(OpenApiTest, EveryExampleOfTheTreeOpensAndRuns) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();
  EXPECT_EQ(http(port_, HttpRequest{"GET", "/api/examples", ""}).status, 401);
  const HttpResponse listed = http(port_, HttpRequest{"GET", "/api/examples", kViewer});
  EXPECT_REPLY(listed, 200);
  const json examples = body_of(listed)["examples"];

  // The examples are the tree's, byte for byte.
  std::set<std::string> in_tree;
  for (const auto& entry : std::filesystem::directory_iterator(CHIMERA_EXAMPLES_DIR))
    if (entry.path().extension() == ".yaml") in_tree.insert(entry.path().filename().string());
  std::set<std::string> offered;
  for (const auto& e : examples) offered.insert(e["name"].get<std::string>());
  EXPECT_EQ(offered, in_tree);
  ASSERT_GE(offered.size(), 5U);

  for (const auto& e : examples) {
    const std::string name = e["name"];
    SCOPED_TRACE(name);
    EXPECT_EQ(e["text"], read_text(std::filesystem::path(CHIMERA_EXAMPLES_DIR) / name));
    EXPECT_FALSE(e["title"].get<std::string>().empty());
    // Under a name of its own: another test may run the same example meanwhile, and a subsystem's
    // shared memory is named after it.
    const std::string subsystem = unique_name();
    const HttpResponse opened = open(name, renamed(e["text"], subsystem));
    ASSERT_EQ(opened.status, 200) << opened.body;
    const json reply = body_of(opened);
    EXPECT_EQ(reply["verb"], "open");
    EXPECT_EQ(reply["file"], name);
    EXPECT_EQ(reply["text"].get<std::string>().rfind("opened " + name + ": subsystem ", 0), 0U) << reply["text"];
    // The file's own subsystem, its start configuration on, and it runs.
    EXPECT_EQ(reply["status"]["subsystem"], subsystem);
    EXPECT_REPLY(run("wait 200ms"), 200);
    const json now = status();
    EXPECT_EQ(now["subsystem"], subsystem);
    EXPECT_EQ(now["configuration"], reply["configuration"]);
    std::size_t on = 0;
    for (const auto& t : now["tasks"]) {
      if (t["state"] != "ON") continue;
      ++on;
      EXPECT_GT(t["cycles"].get<std::uint64_t>(), 0U) << t;
      EXPECT_EQ(t["missed"], 0) << t;
    }
    EXPECT_GE(on, 2U) << now;
  }
  EXPECT_REPLY(run("quit"), 200);
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
  // What open wrote went with the run.
  EXPECT_TRUE(std::filesystem::is_empty(dir_.file("tmp")));
}

TEST_F(OpenApiTest, AFileThatCannotRunIsRefusedAndChangesNothing) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();
  EXPECT_REPLY(run("wait 50ms"), 200);
  const json before = status();
  const std::string fig4 = read_text(std::filesystem::path(CLI_DATA_DIR) / "net_fig4.yaml");

  // The loader's message: the file as the client named it, the line and the key.
  std::string bad = fig4;
  bad.replace(bad.find("period: 10ms"), 12, "period: 10 ms");
  HttpResponse r = open("mine.yaml", bad);
  EXPECT_REPLY(r, 409);
  const std::string message = body_of(r)["error"]["message"];
  EXPECT_EQ(message.rfind("mine.yaml:7: tasks[0].period: ", 0), 0U) << message;
  EXPECT_EQ(message.find(dir_.file("tmp")), std::string::npos) << message;
  // Not legal at its start configuration: the set difference named.
  std::string illegal = fig4;
  illegal.replace(illegal.find("[traj, pid, robot]"), 18, "[traj, robot]");
  r = open("illegal.yaml", illegal);
  EXPECT_REPLY(r, 409);
  EXPECT_NE(body_of(r)["error"]["message"].get<std::string>().find("tau_r"), std::string::npos) << r.body;
  EXPECT_REPLY(open("empty.yaml", ""), 409);

  // What is wrong with the request itself.
  EXPECT_REPLY(open("fig4.yaml", fig4, kViewer), 403);
  EXPECT_REPLY(open("../fig4.yaml", fig4), 400);
  EXPECT_REPLY(open(".hidden.yaml", fig4), 400);
  EXPECT_REPLY(open("a/b.yaml", fig4), 400);
  EXPECT_REPLY(open_body("{"), 400);
  EXPECT_REPLY(open_body(R"({"file": "x.yaml"})"), 400);
  EXPECT_REPLY(open_body(R"({"file": "x.yaml", "text": 5})"), 400);
  EXPECT_REPLY(open_body(R"({"file": "x.yaml", "text": "", "path": "/etc"})"), 400);
  EXPECT_REPLY(http(port_, HttpRequest{"GET", "/api/open", kOperator}), 405);
  // The shell's open FILE reads the server's disk: not over the network.
  r = run("open " + private_copy(dir_, "net_fig4.yaml"));
  EXPECT_REPLY(r, 400);

  // Nothing changed: the same subsystem, its tasks as they were, running on.
  const json after = status();
  EXPECT_EQ(after["subsystem"], before["subsystem"]);
  EXPECT_EQ(after["configuration"], before["configuration"]);
  ASSERT_EQ(after["tasks"].size(), before["tasks"].size());
  for (std::size_t i = 0; i < after["tasks"].size(); ++i)
    EXPECT_EQ(after["tasks"][i]["state"], before["tasks"][i]["state"]);
  EXPECT_REPLY(run("quit"), 200);
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
}

TEST_F(OpenApiTest, AnOpenedFileWithAModuleProcessRunsItOnTheRealClock) {
  // visual_servo's vision task runs in a process of its own, whose worker reads the file: the
  // one open wrote on the server.
  auto p = start("real");
  ASSERT_GT(port_, 0) << p->err();
  const std::string name = unique_name();
  std::string text = renamed(read_text(std::filesystem::path(CHIMERA_EXAMPLES_DIR) / "visual_servo.yaml"), name);
  // Its hard tasks soft: a shared machine may miss a 1 ms deadline, which would end the run with
  // 1 and is not this test's subject.
  std::size_t softened = 0;
  for (auto at = text.find("    period: 1ms\n"); at != std::string::npos; at = text.find("    period: 1ms\n", at + 1)) {
    text.insert(at + 16, "    criticality: soft\n");
    ++softened;
  }
  ASSERT_EQ(softened, 5U) << "the example changed: adapt this test";
  const HttpResponse opened = open("visual_servo.yaml", text);
  ASSERT_EQ(opened.status, 200) << opened.body << p->err();
  EXPECT_REPLY(run("wait 500ms"), 200);
  const json now = status();
  EXPECT_EQ(now["subsystem"], name);
  bool seen = false;
  for (const auto& t : now["tasks"]) {
    if (t["name"] != "vision") continue;
    seen = true;
    EXPECT_EQ(t["state"], "ON") << t;
    EXPECT_GT(t["cycles"].get<std::uint64_t>(), 0U) << t;  // its worker read the file and runs it
  }
  EXPECT_TRUE(seen) << now;
  // The saved file is the opened one's subsystem.
  const HttpResponse saved = command(port_, kViewer, "save");
  EXPECT_REPLY(saved, 200);
  EXPECT_NE(body_of(saved)["yaml"].get<std::string>().find("subsystem: " + name), std::string::npos);
  EXPECT_REPLY(run("quit"), 200);
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
}

}  // namespace
}  // namespace chimera::test
