// The network control API (docs/control-api.md) against a real `chimera run --listen` on
// loopback: every shell command over HTTP, the errors of bad requests, tokens and roles, bodies
// too large, many clients at once and clients that misbehave.

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "chimera_process.hpp"
#include "http_client.hpp"
#include "run_chimera.hpp"
#include "support/json_text.hpp"
#include "support/text_search.hpp"

namespace chimera::test {
namespace {

using nlohmann::json;

const std::string kOperator = "operator-token-0123456789abcdef";
const std::string kViewer = "viewer-token-0123456789abcdef";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

json body_of(const HttpResponse& r) {
  json doc = test::parse_json(r.body, false);
  return doc.is_discarded() ? json{{"unparsed", r.body}} : doc;
}

// The states of every task, {"pid": "ON", ...}, as the API reports them.
std::map<std::string, std::string> states(int port) {
  const HttpResponse r = http(port, HttpRequest{"GET", "/api/status", kOperator});
  std::map<std::string, std::string> out;
  const json doc = body_of(r);
  if (r.status != 200) return out;
  for (const auto& t : doc["status"]["tasks"]) out[t["name"]] = t["state"];
  return out;
}

class ControlApiHttpTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { std::signal(SIGPIPE, SIG_IGN); }  // a test writes to sockets the server closed

  std::string token_file() {
    const std::string path = dir_.file("tokens");
    write_text(path, "# the tests' tokens\noperator " + kOperator + "\nviewer " + kViewer + "\n");
    ::chmod(path.c_str(), 0600);
    return path;
  }

  // `chimera run` of the test subsystem with the API on a free loopback port.
  std::unique_ptr<ChimeraProcess> start(const std::string& clock = "virtual", std::vector<std::string> more = {}) {
    std::vector<std::string> args{
        "run",       private_copy(dir_, "net_fig4.yaml"), "--clock", clock, "--listen", "127.0.0.1:0", "--token-file",
        token_file()};
    args.insert(args.end(), more.begin(), more.end());
    auto p = std::make_unique<ChimeraProcess>(dir_, args);
    port_ = p->port();
    return p;
  }

  HttpResponse run(const std::string& line, const std::string& token = kOperator) const {
    return command(port_, token, line);
  }

  TempDir dir_;
  int port_ = 0;
};

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_REPLY(response, code) EXPECT_EQ((response).status, code) << (response).body

TEST_F(ControlApiHttpTest, EveryShellCommandOverHttp) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();

  auto r = run("status");
  EXPECT_REPLY(r, 200);
  json doc = body_of(r);
  EXPECT_EQ(doc["ok"], true);
  EXPECT_EQ(doc["verb"], "status");
  EXPECT_TRUE(contains(doc["text"], "pid")) << doc;
  EXPECT_EQ(doc["status"]["configuration"], "pid_control");
  EXPECT_EQ(doc["status"]["clock"], "virtual");
  EXPECT_EQ(states(port_),
            (std::map<std::string, std::string>{
                {"traj", "ON"}, {"pid", "ON"}, {"robot", "ON"}, {"load", "NOT-CREATED"}, {"faulty", "NOT-CREATED"}}));

  // wait: the virtual clock advances by exactly that much.
  r = run("wait 100ms");
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["now_ns"], 100'000'000);

  // The lifecycle, one signal at a time, in the verb-and-args form as well.
  EXPECT_REPLY(run("spawn load"), 200);
  EXPECT_EQ(states(port_)["load"], "OFF");
  HttpRequest on{"POST", "/api/command", kOperator};
  on.body = R"({"verb": "on", "args": ["load"]})";
  r = http(port_, on);
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["text"], "load: ON\n");
  EXPECT_REPLY(run("off load"), 200);
  EXPECT_EQ(states(port_)["load"], "OFF");
  EXPECT_REPLY(run("kill load"), 200);
  EXPECT_EQ(states(port_)["load"], "NOT-CREATED");

  // A task in ERROR, and clear.
  EXPECT_REPLY(run("spawn faulty"), 200);
  EXPECT_REPLY(run("on faulty"), 200);
  EXPECT_REPLY(run("wait 100ms"), 200);
  EXPECT_EQ(states(port_)["faulty"], "ERROR");
  r = run("clear faulty");
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["text"], "faulty: OFF\n");
  EXPECT_REPLY(run("kill faulty"), 200);

  // switch, to a configuration of the file and to none.
  r = run("switch loaded");
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["configuration"], "loaded");
  EXPECT_EQ(states(port_)["load"], "ON");
  r = run("switch nosuch");
  EXPECT_REPLY(r, 409);
  EXPECT_EQ(body_of(r)["error"]["code"], "refused");
  EXPECT_TRUE(contains(body_of(r)["error"]["message"], "nosuch")) << r.body;

  // get and set, as a command and as a resource.
  r = run("get theta_d");
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["values"].size(), 6U) << r.body;
  r = run("set theta_d 0 0 0 0 0 0");
  EXPECT_REPLY(r, 409);
  EXPECT_EQ(body_of(r)["error"]["message"], "theta_d is produced by task 'traj', which is ON");
  EXPECT_REPLY(run("off traj"), 200);
  r = run("set theta_d 0.5 -0.25 1e-3 0 0 2");
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["values"], test::parse_json("[0.5, -0.25, 0.001, 0, 0, 2]"));
  HttpRequest variable{"GET", "/api/variables/theta_d", kViewer};
  r = http(port_, variable);
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["values"], test::parse_json("[0.5, -0.25, 0.001, 0, 0, 2]"));
  variable.path = "/api/variables/nosuch";
  r = http(port_, variable);
  EXPECT_REPLY(r, 404);
  EXPECT_EQ(body_of(r)["error"]["message"], "no state variable named 'nosuch'");

  // stats: the table, one task, and a task that does not exist.
  r = run("stats");
  EXPECT_REPLY(r, 200);
  EXPECT_GT(body_of(r)["stats"]["tasks"]["pid"]["cycles"].get<int>(), 0) << r.body;
  r = run("stats pid");
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["stats"]["tasks"].size(), 1U) << r.body;
  EXPECT_REPLY(run("stats nosuch"), 409);

  // help and the list of commands with the role each needs.
  r = run("help");
  EXPECT_REPLY(r, 200);
  EXPECT_TRUE(contains(body_of(r)["text"], "switch CONFIG")) << r.body;
  r = http(port_, HttpRequest{"GET", "/api/commands", kViewer});
  EXPECT_REPLY(r, 200);
  std::map<std::string, std::string> roles;
  const json commands = body_of(r)["commands"];
  for (const auto& c : commands) roles[c["verb"].get<std::string>()] = c["role"].get<std::string>();
  EXPECT_EQ(roles["status"], "viewer");
  EXPECT_EQ(roles["on"], "operator");
  EXPECT_EQ(roles["add"], "operator");   // live assembly changes the subsystem
  EXPECT_EQ(roles["verify"], "viewer");  // checks, changes nothing
  EXPECT_EQ(roles["save"], "viewer");    // over the network save only replies with the file
  EXPECT_EQ(roles["dump"], "operator");  // writes files on the server's machine
  EXPECT_EQ(roles["open"], "operator");  // replaces the subsystem
  EXPECT_EQ(roles.size(), 20U);

  // quit stops the subsystem cleanly: the process ends with the timing table.
  r = run("quit");
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["stopping"], true);
  // faulty went to ERROR: a hard task failed, so the run's exit code is 1.
  EXPECT_EQ(p->wait_exit(), 1) << p->err();
  EXPECT_TRUE(contains(p->out(), "pid")) << p->out();
}

TEST_F(ControlApiHttpTest, ARefusedCommandSaysWhatTheShellSaysAndChangesNothing) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();
  const auto before = states(port_);
  for (const std::string line : {"on pid", "clear robot", "spawn traj", "off pid nosuch", "switch nosuch"}) {
    const HttpResponse r = run(line);
    EXPECT_REPLY(r, 409);
    const std::string message = body_of(r)["error"]["message"];
    // The shell on the same process prints the very same line.
    p->send(line + "\n");
    for (int i = 0; i < 100 && !contains(p->out(), message); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_TRUE(contains(p->out(), message + "\n")) << line << ": " << message << "\n" << p->out();
  }
  EXPECT_EQ(states(port_), before);
  EXPECT_EQ(body_of(run("on pid"))["error"]["message"], "on pid: task is ON, on needs OFF");
  p->send("quit\n");
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
}

TEST_F(ControlApiHttpTest, BadRequestsAreClearJsonErrors) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();
  const auto before = states(port_);
  struct Case {
    std::string method, path, body;
    int status;
    std::string code, message_part;
  };
  const std::vector<Case> cases{
      {"POST", "/api/command", "{\"command\": ", 400, "bad_json", "the body is not JSON"},
      {"POST", "/api/command", "off pid", 400, "bad_json", "the body is not JSON"},
      {"POST", "/api/command", "", 400, "bad_json", "the body is not JSON"},
      // A number past a double's range: nlohmann's parse throws out_of_range, not parse_error; it
      // ended the process (the api_request fuzzer's regressions/api_request/json_number_overflow).
      {"POST", "/api/command", R"({"verb": 1E99999, "args": ["traj"]})", 400, "bad_json", "number overflow"},
      {"POST", "/api/command", "[\"off\", \"pid\"]", 400, "bad_request", "JSON object"},
      {"POST", "/api/command", R"({"command": 3})", 400, "bad_request", "command: a string"},
      {"POST", "/api/command", R"({"command": "off pid", "force": true})", 400, "bad_request", "unknown key 'force'"},
      {"POST", "/api/command", R"({"command": "off pid", "verb": "off"})", 400, "bad_request", "not both"},
      {"POST", "/api/command", R"({"verb": "off", "args": ["pid robot"]})", 400, "bad_request", "one word"},
      {"POST", "/api/command", R"({"verb": "off", "args": [{"task": "pid"}]})", 400, "bad_request", "args[0]"},
      {"POST", "/api/command", R"({"command": "frobnicate pid"})", 400, "bad_command",
       "unknown command 'frobnicate' (try help)"},
      {"POST", "/api/command", R"({"command": "kill pid robot"})", 400, "bad_command", "kill takes 1 argument"},
      {"POST", "/api/command", R"({"command": "set theta_d x"})", 400, "bad_command", "'x' is not a number"},
      {"POST", "/api/command", R"({"command": "   "})", 400, "bad_command", "empty command"},
      {"POST", "/api/command", R"({"command": "wait 61s"})", 400, "bad_command", "wait: at most 60s over the network"},
      {"GET", "/api/command", "", 405, "method_not_allowed", "POST only"},
      {"DELETE", "/api/status", "", 405, "method_not_allowed", "GET only"},
      {"GET", "/api/nosuch", "", 404, "not_found", "no such endpoint"},
      {"GET", "/api", "", 404, "not_found", "no such endpoint"},
  };
  for (const auto& c : cases) {
    HttpRequest request{c.method, c.path, kOperator};
    request.body = c.body;
    const HttpResponse r = http(port_, request);
    EXPECT_EQ(r.status, c.status) << c.method << " " << c.path << " " << c.body << "\n" << r.body;
    const json doc = body_of(r);
    EXPECT_EQ(doc["ok"], false) << r.body;
    EXPECT_EQ(doc["error"]["code"], c.code) << c.body << "\n" << r.body;
    EXPECT_TRUE(contains(doc["error"]["message"], c.message_part)) << c.body << "\n" << r.body;
    EXPECT_TRUE(contains(r.header("content-type"), "application/json")) << r.header("content-type");
    if (c.status == 405) {
      EXPECT_FALSE(r.header("allow").empty());
    }
  }
  EXPECT_EQ(states(port_), before);
}

TEST_F(ControlApiHttpTest, RequestsWithoutTheRightTokenGet401AndChangeNothing) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();
  const auto before = states(port_);
  std::vector<HttpRequest> bad;
  for (const std::string path : {"/api/command", "/api/status", "/api/nosuch", "/api/variables/theta_d"}) {
    HttpRequest none{path == "/api/command" ? "POST" : "GET", path, ""};
    none.body = path == "/api/command" ? R"({"command": "off pid"})" : "";
    bad.push_back(none);
    HttpRequest wrong = none;
    wrong.token = kOperator + "x";
    bad.push_back(wrong);
    wrong.token = kOperator.substr(0, kOperator.size() - 1) + "X";  // one character off, same length
    bad.push_back(wrong);
    HttpRequest basic = none;
    basic.authorization = "Basic " + kOperator;
    bad.push_back(basic);
  }
  for (const auto& request : bad) {
    const HttpResponse r = http(port_, request);
    EXPECT_EQ(r.status, 401) << request.path << " " << request.token << "\n" << r.body;
    EXPECT_EQ(body_of(r)["error"]["code"], "unauthorized");
    EXPECT_TRUE(contains(r.header("www-authenticate"), "Bearer")) << r.header("www-authenticate");
  }
  EXPECT_EQ(states(port_), before);
  // The scheme's name is case-insensitive.
  HttpRequest lower{"GET", "/api/whoami", ""};
  lower.authorization = "bearer " + kOperator;
  EXPECT_EQ(body_of(http(port_, lower))["role"], "operator");
}

TEST_F(ControlApiHttpTest, AViewerTokenReadsButCannotWrite) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();
  EXPECT_EQ(body_of(http(port_, HttpRequest{"GET", "/api/whoami", kViewer}))["role"], "viewer");
  EXPECT_REPLY(run("wait 20ms"), 200);  // so that get has a value to read
  for (const std::string line : {"status", "stats", "stats pid", "get theta_m", "help"})
    EXPECT_REPLY(run(line, kViewer), 200);
  const auto before = states(port_);
  for (const std::string line :
       {"off pid", "kill robot", "spawn load", "switch loaded", "set tau_r 0 0 0 0 0 0", "wait 1s", "quit"}) {
    const HttpResponse r = run(line, kViewer);
    EXPECT_REPLY(r, 403);
    EXPECT_EQ(body_of(r)["error"]["code"], "forbidden") << r.body;
  }
  EXPECT_EQ(states(port_), before);
  EXPECT_TRUE(p->running());
  EXPECT_EQ(body_of(http(port_, HttpRequest{"GET", "/api/status", kViewer}))["status"]["now_ns"], 20'000'000);
}

TEST_F(ControlApiHttpTest, BodiesLargerThanTheBoundAreRefused) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();
  constexpr std::size_t kBound = std::size_t{64} * 1024;
  // Declared too large: refused before a byte of it is read.
  HttpRequest declared{"POST", "/api/command", kOperator};
  declared.body = R"({"command": "off pid"})";
  declared.declared_length = std::to_string(100 * 1024 * 1024);
  HttpResponse r = http(port_, declared);
  EXPECT_REPLY(r, 413);
  EXPECT_EQ(body_of(r)["error"]["code"], "payload_too_large");
  // Chunked, without a length: refused once the bound is passed.
  HttpRequest chunked{"POST", "/api/command", kOperator};
  chunked.body = R"({"command": "off pid")" + std::string(kBound, ' ') + "}";
  chunked.chunked = true;
  r = http(port_, chunked);
  EXPECT_REPLY(r, 413);
  // At the bound exactly, a body is taken.
  HttpRequest padded{"POST", "/api/command", kOperator};
  padded.body = R"({"command": "status"})";
  padded.body += std::string(kBound - padded.body.size(), ' ');
  EXPECT_REPLY(http(port_, padded), 200);
  padded.body += " ";
  EXPECT_REPLY(http(port_, padded), 413);
  // Without the token, too large is still 401 first.
  declared.token.clear();
  EXPECT_REPLY(http(port_, declared), 401);
  EXPECT_EQ(states(port_)["pid"], "ON");
}

TEST_F(ControlApiHttpTest, ManyClientsAtOnce) {
  auto p = start();
  ASSERT_GT(port_, 0) << p->err();
  constexpr int kClients = 48;
  constexpr int kRequests = 10;
  std::atomic<int> ok{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c) {
    clients.emplace_back([&, c] {
      for (int i = 0; i < kRequests; ++i) {
        const HttpResponse r =
            (c + i) % 2 == 0 ? command(port_, kViewer, "status") : command(port_, kOperator, "wait 1ms");
        if (r.status == 200) ++ok;
      }
    });
  }
  // The shell drives the same subsystem meanwhile.
  for (int i = 0; i < 20; ++i) p->send("wait 1ms\nstatus\n");
  for (auto& t : clients) t.join();
  EXPECT_EQ(ok.load(), kClients * kRequests);
  // Every wait happened, one at a time: the network's 240 and the shell's 20, 1 ms each (the
  // shell's may still be under way).
  std::int64_t now = 0;
  for (int i = 0; i < 200 && now != 260'000'000; ++i) {
    if (i > 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    now = body_of(http(port_, HttpRequest{"GET", "/api/status", kViewer}))["status"]["now_ns"].get<std::int64_t>();
  }
  EXPECT_EQ(now, 260'000'000);
  p->send("quit\n");
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
}

TEST_F(ControlApiHttpTest, StalledClientsSlowNeitherOtherClientsNorTasks) {
  auto p = start("real");
  ASSERT_GT(port_, 0) << p->err();
  auto cycles = [&] {
    const json doc = body_of(http(port_, HttpRequest{"GET", "/api/status", kViewer}));
    std::uint64_t total = 0;
    for (const auto& t : doc["status"]["tasks"]) total += t["cycles"].get<std::uint64_t>();
    return total;
  };
  // Clients that send half a request and wait, and clients that pipeline requests and never
  // read a reply (non-blocking: they stop when the server stops taking their bytes).
  std::vector<int> stalled;
  for (int i = 0; i < 4; ++i) {
    const int fd = connect_to(port_);
    ASSERT_GE(fd, 0);
    const std::string half = "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthoriz";
    ASSERT_GT(::send(fd, half.data(), half.size(), MSG_NOSIGNAL), 0);
    stalled.push_back(fd);
  }
  const std::string one =
      "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + kViewer + "\r\n\r\n";
  std::string many;
  for (int i = 0; i < 2000; ++i) many += one;
  for (int i = 0; i < 4; ++i) {
    const int fd = connect_to(port_);
    ASSERT_GE(fd, 0);
    ::fcntl(fd, F_SETFL, O_NONBLOCK);
    const int small = 4096;
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
    std::size_t sent = 0;
    for (int tries = 0; tries < 200 && sent < many.size(); ++tries) {
      const ssize_t n = ::send(fd, many.data() + sent, many.size() - sent, MSG_NOSIGNAL);
      if (n > 0)
        sent += static_cast<std::size_t>(n);
      else
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    stalled.push_back(fd);
  }
  const std::uint64_t before = cycles();
  // Others are served meanwhile, and the tasks run on.
  for (int i = 0; i < 20; ++i) EXPECT_REPLY(http(port_, HttpRequest{"GET", "/api/status", kViewer}, 4000), 200);
  EXPECT_REPLY(run("off traj"), 200);
  EXPECT_REPLY(run("on traj"), 200);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_GT(cycles(), before);
  for (int fd : stalled) ::close(fd);
  p->send("quit\n");
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
}

TEST_F(ControlApiHttpTest, AGeneratedTokenIsPrintedOnceAndWrittenPrivately) {
  const std::vector<std::string> args{"run", private_copy(dir_, "net_fig4.yaml"), "--clock", "virtual", "--listen",
                                      "0"};
  auto p = std::make_unique<ChimeraProcess>(dir_, args, std::vector<std::string>{"XDG_RUNTIME_DIR=" + dir_.path()});
  port_ = p->port();
  ASSERT_GT(port_, 0) << p->err();
  const std::string err = p->err();
  const std::string path = test::text_after(err, "tokens in ", " ;)\n").value_or("");
  ASSERT_TRUE(contains(err, "tokens in " + path + "; the operator's is in the page's link below")) << err;
  const std::string page = "Onika, the page, on http://127.0.0.1:" + std::to_string(port_) + "/#token=";
  const std::string token = test::text_after(err, page, "\n").value_or("");
  ASSERT_EQ(token.size(), 64U) << err;
  ASSERT_TRUE(test::only_of(token, "0123456789abcdef")) << token;
  EXPECT_EQ(
      path,
      dir_.path() + "/chimera/" +
          test::parse_json(body_of(command(port_, token, "status"))["status"]["subsystem"].dump()).get<std::string>() +
          "-" + std::to_string(port_) + ".token");
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600U);
  const std::string file = read_text(path);
  EXPECT_TRUE(contains(file, "operator " + token + "\n")) << file;
  const std::string viewer_token = test::text_after(file, "viewer ", "\n").value_or("");
  ASSERT_EQ(viewer_token.size(), 64U) << file;
  ASSERT_TRUE(test::only_of(viewer_token, "0123456789abcdef")) << file;
  EXPECT_EQ(body_of(http(port_, HttpRequest{"GET", "/api/whoami", viewer_token}))["role"], "viewer");
  EXPECT_EQ(err.find(viewer_token), std::string::npos) << "the viewer token is only in the file";
  EXPECT_EQ(command(port_, token, "status").status, 200);
  // Printed once: the token appears on stderr one time, and never on stdout.
  EXPECT_EQ(err.find(token), err.rfind(token));
  EXPECT_EQ(command(port_, token, "quit").status, 200);
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
  EXPECT_FALSE(contains(p->out(), token));
  EXPECT_NE(::access(path.c_str(), F_OK), 0) << "the token file goes with the run";
}

TEST_F(ControlApiHttpTest, TheListenAddressAndTokenFileAreChecked) {
  const std::string file = quoted(private_copy(dir_, "net_fig4.yaml"));
  const std::string tokens = token_file();
  const std::vector<std::string> bad_options{"--listen nonsense", "--listen 127.0.0.1:99999", "--listen 1.2.3:80",
                                             "--listen ::1:80",   "--listen 127.0.0.1:",      "--token-file " + tokens};
  for (const std::string& bad : bad_options) {
    const Outcome o = run_chimera(dir_, "run " + file + " --clock virtual --for 10ms " + bad);
    EXPECT_EQ(o.exit_code, 2) << bad << "\n" << o.err;
    EXPECT_TRUE(contains(o.err, bad.substr(0, bad.find(' ')))) << bad << "\n" << o.err;
  }
  ::chmod(tokens.c_str(), 0644);
  Outcome o =
      run_chimera(dir_, "run " + file + " --clock virtual --for 10ms --listen 0 --token-file " + quoted(tokens));
  EXPECT_EQ(o.exit_code, 2) << o.err;
  EXPECT_TRUE(contains(o.err, "other users may read it")) << o.err;
  // Another address than loopback only when asked, with one warning line.
  ::chmod(tokens.c_str(), 0600);
  o = run_chimera(dir_,
                  "run " + file + " --clock virtual --for 10ms --listen 0.0.0.0:0 --token-file " + quoted(tokens));
  EXPECT_EQ(o.exit_code, 0) << o.err;
  EXPECT_TRUE(contains(o.err, "warning: --listen 0.0.0.0:")) << o.err;
  o = run_chimera(dir_, "run " + file + " --clock virtual --for 10ms --listen 0 --token-file " + quoted(tokens));
  EXPECT_EQ(o.exit_code, 0) << o.err;
  EXPECT_FALSE(contains(o.err, "warning")) << o.err;
  EXPECT_TRUE(contains(o.err, "control API on http://127.0.0.1:")) << o.err;
}

TEST_F(ControlApiHttpTest, ServeStartsAnEmptySubsystem) {
  auto p = std::make_unique<ChimeraProcess>(
      dir_, std::vector<std::string>{"serve", "--listen", "127.0.0.1:0", "--token-file", token_file()});
  port_ = p->port();
  ASSERT_GT(port_, 0) << p->err();
  const HttpResponse r = run("status");
  EXPECT_REPLY(r, 200);
  EXPECT_EQ(body_of(r)["status"]["tasks"], json::array());
  EXPECT_EQ(body_of(r)["status"]["configuration"], "empty");
  EXPECT_REPLY(run("switch other"), 409);
  // GET / is Onika, the page, and /static/ its files (embedded at build time), with no token;
  // nothing else is served outside /api/.
  const HttpResponse page = http(port_, HttpRequest{"GET", "/", ""});
  EXPECT_EQ(page.status, 200);
  EXPECT_TRUE(contains(page.header("content-type"), "text/html"));
  EXPECT_TRUE(contains(page.body, "/static/js/main.js")) << page.body;
  EXPECT_TRUE(contains(page.header("content-security-policy"), "default-src 'self'"));
  const HttpResponse script = http(port_, HttpRequest{"GET", "/static/js/canvas.js", ""});
  EXPECT_EQ(script.status, 200);
  EXPECT_TRUE(contains(script.header("content-type"), "text/javascript"));
  EXPECT_TRUE(contains(script.body, "export class Canvas"));
  EXPECT_EQ(http(port_, HttpRequest{"GET", "/static/nosuch.js", ""}).status, 404);
  EXPECT_EQ(http(port_, HttpRequest{"GET", "/static/../CMakeLists.txt", ""}).status, 404);
  EXPECT_EQ(http(port_, HttpRequest{"GET", "/nosuch", ""}).status, 404);
  EXPECT_EQ(http(port_, HttpRequest{"POST", "/", ""}).status, 405);
  // The documents the page is drawn from need a token as every /api/ request does.
  EXPECT_EQ(http(port_, HttpRequest{"GET", "/api/modules", ""}).status, 401);
  const HttpResponse modules = http(port_, HttpRequest{"GET", "/api/modules", kViewer});
  EXPECT_REPLY(modules, 200);
  const auto library = body_of(modules);  // a named copy: a range-for over a temporary's member dangles
  EXPECT_GT(library["modules"].size(), 10U);
  // The join connector is marked as one (Onika draws it as the paper's Figure 3 does); nothing else is.
  for (const auto& m : library["modules"])
    EXPECT_EQ(m["connector"], m["name"] == "join_weighted_average" ? "join" : "") << m["name"];
  const HttpResponse model = http(port_, HttpRequest{"GET", "/api/subsystem", kViewer});
  EXPECT_REPLY(model, 200);
  EXPECT_EQ(body_of(model)["subsystem"]["configuration"], "empty");
  EXPECT_EQ(http(port_, HttpRequest{"POST", "/api/subsystem", kOperator}).status, 405);
  EXPECT_REPLY(run("quit"), 200);
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
}

TEST_F(ControlApiHttpTest, LiveAssemblyOverHttp) {
  auto p = std::make_unique<ChimeraProcess>(
      dir_, std::vector<std::string>{"serve", "--listen", "127.0.0.1:0", "--token-file", token_file()});
  port_ = p->port();
  ASSERT_GT(port_, 0) << p->err();
  // add: the task entry as JSON (a YAML flow mapping too), or on the shell's line.
  HttpRequest add_robot{"POST", "/api/command", kOperator};
  add_robot.body = R"({"verb": "add", "args": [{"name": "robot", "module": "robot_torque", "period": "1ms"}]})";
  const HttpResponse robot = http(port_, add_robot);
  EXPECT_REPLY(robot, 200);
  EXPECT_EQ(body_of(robot)["task"], "robot");
  // With a parameter and a rename, as a file's entry has them: traj's theta_d is theta_ref here.
  EXPECT_REPLY(run("add {name: traj, module: joint_traj_gen, period: 1ms, criticality: soft, "
                   "params: {segment_time: 1.5}, rename: {theta_d: theta_ref}}"),
               200);
  EXPECT_REPLY(run("add {name: traj, module: joint_traj_gen, period: 1ms}"), 409);  // already there
  EXPECT_REPLY(run("add {name: bad, module: joint_traj_gen, period: 1ms, params: {segment_time: 0}}"), 409);
  EXPECT_REPLY(run("add {name: x, module: cpu_load}", kViewer), 403);
  // define and verify: the set difference, and nothing switched.
  const HttpResponse defined = run("define fig4 traj robot");
  EXPECT_REPLY(defined, 200);
  EXPECT_EQ(body_of(defined)["legal"], false);
  const HttpResponse verified = run("verify fig4", kViewer);
  EXPECT_REPLY(verified, 200);
  const json v = body_of(verified);
  EXPECT_EQ(v["legal"], false);
  ASSERT_EQ(v["violations"].size(), 1U) << verified.body;
  EXPECT_EQ(v["violations"][0]["rule"], 2);
  EXPECT_EQ(v["violations"][0]["variable"], "tau_r");
  EXPECT_EQ(v["violations"][0]["reason"], "tau_r has no producer (read by robot)");
  EXPECT_REPLY(run("switch fig4"), 409);
  EXPECT_REPLY(run("add {name: pid, module: pid_joint, period: 1ms, params: {kp: [40]}, rename: {theta_d: theta_ref}}"),
               200);
  EXPECT_REPLY(run("add {name: spare, module: cpu_load, period: 10ms}"), 200);
  EXPECT_REPLY(run("define fig4 traj pid robot"), 200);
  EXPECT_EQ(body_of(run("verify fig4"))["legal"], true);
  EXPECT_REPLY(run("switch fig4"), 200);
  EXPECT_REPLY(run("wait 100ms"), 200);
  EXPECT_EQ(states(port_)["pid"], "ON");
  EXPECT_REPLY(run("remove pid"), 409);
  EXPECT_REPLY(run("remove spare"), 200);
  EXPECT_EQ(states(port_).count("spare"), 0U);
  // save: over the network the reply carries the file, which chimera verify accepts.
  EXPECT_REPLY(run("save /tmp/anything.yaml"), 400);
  const HttpResponse saved = run("save", kViewer);
  EXPECT_REPLY(saved, 200);
  const std::string path = dir_.file("saved.yaml");
  write_text(path, body_of(saved)["yaml"].get<std::string>());
  const auto checked = run_chimera(dir_, "verify " + path);
  EXPECT_EQ(checked.exit_code, 0) << checked.out << checked.err;
  // ... and starts the same subsystem: the same tasks (modules, periods, parameters, ports bound
  // to the same variables), the same configurations, the same one on.
  const json assembled = body_of(http(port_, HttpRequest{"GET", "/api/subsystem", kViewer}))["subsystem"];
  EXPECT_REPLY(run("quit"), 200);
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
  const TempDir second;  // its own output files: the first run's name its port too
  auto again = std::make_unique<ChimeraProcess>(
      second, std::vector<std::string>{"run", path, "--listen", "127.0.0.1:0", "--token-file", token_file()});
  port_ = again->port();
  ASSERT_GT(port_, 0) << again->err();
  const HttpResponse model = http(port_, HttpRequest{"GET", "/api/subsystem", kViewer});
  EXPECT_REPLY(model, 200);
  const json started = body_of(model)["subsystem"];
  ASSERT_TRUE(started.is_object()) << model.body << again->err();
  ASSERT_EQ(assembled["tasks"].size(), 3U) << assembled;
  EXPECT_EQ(started["tasks"], assembled["tasks"]);
  EXPECT_EQ(started["configurations"], assembled["configurations"]);
  EXPECT_EQ(started["configuration"], "fig4");
  EXPECT_EQ(states(port_), (std::map<std::string, std::string>{{"traj", "ON"}, {"pid", "ON"}, {"robot", "ON"}}));
  EXPECT_REPLY(run("quit"), 200);
  EXPECT_EQ(again->wait_exit(), 0) << again->err();
}

// dump over the network: the recorder's last seconds go below the run's dump directory; DIR, a
// path anywhere on the server's machine, is refused as save FILE is, and a viewer may not write.
TEST_F(ControlApiHttpTest, DumpWritesBelowTheRunsDumpDirectory) {
  const std::string dumps = dir_.file("dumps");
  auto p = start("virtual", {"--record", "1s", "--dump-dir", dumps});
  ASSERT_GT(port_, 0) << p->err();
  EXPECT_REPLY(run("wait 200ms"), 200);
  EXPECT_REPLY(run("dump", kViewer), 403);
  EXPECT_REPLY(run("dump " + dir_.file("elsewhere")), 400);
  EXPECT_FALSE(std::filesystem::exists(dir_.file("elsewhere")));
  const HttpResponse dumped = run("dump");
  EXPECT_REPLY(dumped, 200);
  const std::string text = body_of(dumped)["text"];
  EXPECT_TRUE(contains(text, dumps + "/")) << text;
  std::size_t written = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dumps))
    if (std::filesystem::is_regular_file(entry.path() / "variables.csv")) ++written;
  EXPECT_EQ(written, 1U);
  EXPECT_REPLY(run("quit"), 200);
  EXPECT_EQ(p->wait_exit(), 0) << p->err();
}

}  // namespace
}  // namespace chimera::test
