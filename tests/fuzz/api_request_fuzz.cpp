// Fuzz target: the network API's request parser and dispatcher (ControlApi::handle), without
// sockets, on a live subsystem on the virtual clock. An input is
//   METHOD PATH          first line
//   operator|viewer|X    second line: whose token to present (X: sent as the header itself)
//   BODY                 the rest
// so that the fuzzer need not guess a token to get past the 401. Every reply must be a status the
// API documents with a JSON body.
//
// Inputs that would reach outside the process are skipped: `save` writes files, and the modules
// that log to files or open sockets could be added by `add` (or come in a file that /api/open
// opens, which writes only below its own directory of $TMPDIR, removed at exit). What is left
// cannot harm the host.

#include <unistd.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/core/invariant.hpp"
#include "chimera/module/registry.hpp"
#include "chimera/net/control_api.hpp"
#include "fuzz_target.hpp"

namespace {

constexpr std::string_view kOperatorToken = "fuzz-operator-token-0123456789";
constexpr std::string_view kViewerToken = "fuzz-viewer-token-0123456789ab";

constexpr std::string_view kSubsystemFile = R"(subsystem: fuzz_api
tasks:
  - { name: traj, module: joint_traj_gen, period: 1ms, criticality: soft }
  - { name: pid, module: pid_joint, period: 1ms }
  - { name: robot, module: robot_torque, period: 1ms }
configurations:
  pid_control: [traj, pid, robot]
)";

// One subsystem for the whole run: creating its table per input would be most of the time.
// Commands change its state from input to input, which libFuzzer tolerates (and which finds
// sequences a fresh subsystem never meets).
struct Server {
  std::unique_ptr<chimera::Subsystem> subsystem;
  std::unique_ptr<chimera::net::ControlGate> gate;
  std::unique_ptr<chimera::net::ControlApi> api;
};

Server make_server() {
  auto spec = chimera::load_subsystem_text(kSubsystemFile, "fuzz_api.yaml", chimera::Registry::global());
  CHIMERA_INVARIANT(spec.ok(), "the fuzz target's own subsystem file does not load");
  chimera::RunOptions options;
  options.clock = chimera::ClockKind::kVirtual;
  options.realtime_priorities = false;
  options.shm_suffix = "_" + std::to_string(::getpid());  // parallel fuzzers never share a table
  auto subsystem = chimera::Subsystem::create(*spec, chimera::Registry::global(), options);
  if (!subsystem) std::fprintf(stderr, "fuzz api_request: %s\n", subsystem.error().message.c_str());
  CHIMERA_INVARIANT(subsystem.ok(), "the fuzz target's subsystem cannot be created");
  auto tokens = chimera::net::AccessTokens::parse(
      "operator " + std::string(kOperatorToken) + "\nviewer " + std::string(kViewerToken) + "\n", "fuzz");
  CHIMERA_INVARIANT(tokens.ok(), "the fuzz target's tokens do not parse");
  Server s;
  s.subsystem = std::move(subsystem).value();
  s.gate = std::make_unique<chimera::net::ControlGate>(*s.subsystem);
  s.api = std::make_unique<chimera::net::ControlApi>(*s.gate, std::move(tokens).value());
  return s;
}

// Cuts the first line off `text`.
std::string_view take_line(std::string_view& text) {
  const auto newline = text.find('\n');
  const std::string_view line = text.substr(0, newline);
  text.remove_prefix(newline == std::string_view::npos ? text.size() : newline + 1);
  return line;
}

bool reaches_outside(std::string_view input) {
  constexpr std::array<std::string_view, 4> kWords{"save", "data_logger", "udp_command", "teleop_input"};
  for (auto word : kWords)
    if (input.find(word) != std::string_view::npos) return true;
  return false;
}

bool documented_status(int status) {
  constexpr std::array kStatuses{200, 400, 401, 403, 404, 405, 409, 413, 500, 503};
  for (int s : kStatuses)
    if (s == status) return true;
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view input = chimera::fuzz::as_text(data, size);
  if (reaches_outside(input)) return -1;  // -1: libFuzzer keeps it out of the corpus
  static Server server = make_server();

  const std::string_view request_line = take_line(input);
  const std::string_view who = take_line(input);
  const auto blank = request_line.find(' ');
  const std::string bearer_operator = "Bearer " + std::string(kOperatorToken);
  const std::string bearer_viewer = "Bearer " + std::string(kViewerToken);

  chimera::net::ApiRequest request;
  request.method = request_line.substr(0, blank);
  request.path = blank == std::string_view::npos ? std::string_view() : request_line.substr(blank + 1);
  request.authorization = who == "operator" ? bearer_operator : who == "viewer" ? bearer_viewer : who;
  request.body = input;
  request.body_too_large = input.size() > chimera::net::ControlApi::kMaxBodyBytes;

  const chimera::net::ApiResponse response = server.api->handle(request);
  CHIMERA_INVARIANT(documented_status(response.status), "the API answered with an undocumented status");
  CHIMERA_INVARIANT(nlohmann::json::accept(response.body), "the API's reply is not JSON");
  return 0;
}
