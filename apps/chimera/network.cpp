#include "network.hpp"

#include <unistd.h>

#include <cstdio>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "stop_request.hpp"

namespace chimera::cli {

namespace {

constexpr const char* kListenHelp =
    "serve the control API (HTTP, under /api/) on [ADDR:]PORT; ADDR is 127.0.0.1 unless given; "
    "port 0: any free port";

}  // namespace

void add_listen_options(CLI::App& command, RunArgs& args) {
  command.add_option("--listen", args.listen, kListenHelp);
  command.add_option("--token-file", args.token_file,
                     "the API's tokens: lines 'operator TOKEN' or 'viewer TOKEN' (mode 0600); default: made now");
}

CLI::App* add_serve_command(CLI::App& app, RunArgs& args) {
  auto* serve = app.add_subcommand("serve", "Serve an empty subsystem on the network control API (no file)");
  args.listen = "127.0.0.1:8080";
  serve->add_option("--listen", args.listen, kListenHelp)->capture_default_str();
  serve->add_option("--token-file", args.token_file,
                    "the API's tokens: lines 'operator TOKEN' or 'viewer TOKEN' (mode 0600); default: made now");
  return serve;
}

SubsystemSpec empty_subsystem() {
  SubsystemSpec spec;
  spec.name = fmt::format("serve_{}", ::getpid());
  spec.file = "(chimera serve)";
  spec.configurations.push_back(ConfigurationSpec{"empty", {}, {}});
  spec.start = "empty";
  return spec;
}

Result<std::optional<NetworkPlan>> plan_network(const RunArgs& args) {
  if (!args.listen) {
    if (args.token_file) {
      fmt::print(stderr, "--token-file: only with --listen\n");
      return make_error(Errc::kInvalidInput, "--token-file without --listen");
    }
    return std::optional<NetworkPlan>{};
  }
  auto address = net::parse_listen_address(*args.listen);
  if (!address) {
    fmt::print(stderr, "{}\n", address.error().message);
    return address.error();
  }
  auto tokens = args.token_file ? net::AccessTokens::load(*args.token_file) : net::AccessTokens::generate();
  if (!tokens) {
    fmt::print(stderr, "{}\n", tokens.error().message);
    return tokens.error();
  }
  return std::optional<NetworkPlan>{NetworkPlan{std::move(*address), std::move(*tokens), !args.token_file}};
}

Network::Network(net::ControlGate& gate, net::AccessTokens tokens)
    : api_(gate, std::move(tokens), [] { request_stop(); }) {}

Result<std::unique_ptr<Network>> Network::start(NetworkPlan plan, net::ControlGate& gate,
                                                const std::string& subsystem_name) {
  const std::optional<std::string> operator_token = plan.tokens.first(net::Role::kOperator);
  const std::string token_text = plan.tokens.file_text();
  std::unique_ptr<Network> network(new Network(gate, std::move(plan.tokens)));
  auto server = net::HttpServer::start(network->api_, plan.address);
  if (!server) {
    fmt::print(stderr, "{}\n", server.error().message);
    return server.error();
  }
  network->server_ = std::move(*server);
  const int port = network->server_->port();
  if (!plan.address.loopback)
    fmt::print(stderr,
               "chimera: warning: --listen {}: other machines can reach the control API, and plain HTTP carries "
               "its token in clear\n",
               plan.address.text(port));
  std::string where = "tokens from --token-file";
  if (plan.generated) {
    auto path = net::default_token_path(fmt::format("{}-{}", subsystem_name, port));
    if (path) {
      if (auto written = net::write_private_file(*path, token_text); written) {
        network->token_path_ = *path;
      } else {
        path = written.error();
      }
    }
    if (!path) {
      fmt::print(stderr, "{}\n", path.error().message);
      return path.error();
    }
    where = fmt::format("tokens in {}; the operator's is in the page's link below", *path);
  }
  fmt::print(stderr, "chimera: control API on {}api/ ({})\n", network->server_->url(), where);
  // The page's link carries the operator's token after '#', which the browser never sends: the
  // page keeps it for the session and takes it out of the address. The token is printed there
  // only, once.
  if (plan.generated && operator_token)
    fmt::print(stderr, "chimera: Onika, the page, on {}#token={}\n", network->server_->url(), *operator_token);
  else
    fmt::print(stderr, "chimera: Onika, the page, on {} (it asks for a token of the token file)\n",
               network->server_->url());
  std::fflush(stderr);
  return network;
}

Network::~Network() {
  if (server_) server_->stop();  // before the subsystem stops: no request meets it stopping
  if (!token_path_.empty()) ::unlink(token_path_.c_str());
}

}  // namespace chimera::cli
