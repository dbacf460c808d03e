#pragma once
// `--listen` and `--token-file` of chimera run and chimera serve: the network control API
// (src/net) started beside the shell, on the same ControlGate, and stopped before the subsystem.

#include <memory>
#include <optional>
#include <string>

#include "chimera/net/access_tokens.hpp"
#include "chimera/net/control_api.hpp"
#include "chimera/net/control_gate.hpp"
#include "chimera/net/http_server.hpp"
#include "chimera/net/listen_address.hpp"
#include "commands.hpp"

namespace CLI {  // NOLINT(readability-identifier-naming): CLI11's namespace, forward-declared
class App;
}  // namespace CLI

namespace chimera::cli {

/// Declares --listen and --token-file on `command`; parsing fills `args`.
void add_listen_options(CLI::App& command, RunArgs& args);
/// Declares `chimera serve` (no file: an empty subsystem, with the network API) on `app`.
CLI::App* add_serve_command(CLI::App& app, RunArgs& args);

/// The subsystem of `chimera serve`: no task and one configuration, `empty`, without tasks; its
/// name is unique to this process (it names the shared memory).
SubsystemSpec empty_subsystem();

/// What --listen and --token-file ask for, checked before anything starts.
struct NetworkPlan {
  net::ListenAddress address;
  net::AccessTokens tokens;
  bool generated = false;  // the tokens were made now (no --token-file): written to a file, printed
};
/// Parses --listen and reads --token-file (or makes tokens); none if --listen was not given.
/// On a problem prints the one message and returns an error (the caller exits kExitInvalid).
Result<std::optional<NetworkPlan>> plan_network(const RunArgs& args);

/// The API served while the subsystem runs; destruction stops it and removes a generated token
/// file.
class Network {
 public:
  /// Binds and serves; prints where (and a generated operator token, once) on stderr, and the
  /// warning for an address other machines reach. `subsystem_name` names the token file.
  static Result<std::unique_ptr<Network>> start(NetworkPlan plan, net::ControlGate& gate,
                                                const std::string& subsystem_name);
  ~Network();
  Network(const Network&) = delete;
  Network& operator=(const Network&) = delete;

 private:
  Network(net::ControlGate& gate, net::AccessTokens tokens);
  net::ControlApi api_;
  std::unique_ptr<net::HttpServer> server_;
  std::string token_path_;  // the generated file, removed at the end; "" with --token-file
};

}  // namespace chimera::cli
