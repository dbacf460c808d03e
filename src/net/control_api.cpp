#include "chimera/net/control_api.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <optional>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api_documents.hpp"
#include "chimera/control/stats_json.hpp"

namespace chimera::net {

namespace {

using nlohmann::json;

// Task names and messages echo what clients sent: never let a stray byte make dump() throw.
std::string dump(const json& doc) { return doc.dump(-1, ' ', false, json::error_handler_t::replace); }

ApiResponse reply(json doc) {
  doc["ok"] = true;
  return ApiResponse{200, dump(doc), {}};
}

// The token of an "Authorization: Bearer TOKEN" header ("" if it is not one); the scheme's name
// is case-insensitive (RFC 9110 section 11.1).
std::string_view bearer_token(std::string_view header) {
  constexpr std::string_view kScheme = "bearer ";
  if (header.size() <= kScheme.size()) return {};
  for (std::size_t i = 0; i < kScheme.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(header[i])) != kScheme[i]) return {};
  std::string_view token = header.substr(kScheme.size());
  while (!token.empty() && token.front() == ' ') token.remove_prefix(1);
  while (!token.empty() && token.back() == ' ') token.remove_suffix(1);
  return token;
}

std::string_view last_line(std::string_view text) {
  while (!text.empty() && text.back() == '\n') text.remove_suffix(1);
  const auto newline = text.rfind('\n');
  return newline == std::string_view::npos ? text : text.substr(newline + 1);
}

json task_json(const TaskSnapshot& t) {
  return json{{"name", t.name},
              {"module", t.module},
              {"state", state_name(t.state)},
              {"period_ns", t.period_ns},
              {"cpu", t.cpu},
              {"cycles", t.stats.cycles},
              {"missed", t.stats.missed},
              {"overruns", t.stats.overruns},
              {"skipped", t.stats.skipped},
              {"last_error", t.last_error}};
}

json status_json(const Subsystem& subsystem) {
  json tasks = json::array();
  for (const auto& t : subsystem.snapshot()) tasks.push_back(task_json(t));
  json configurations = json::array();
  for (auto& name : subsystem.configurations()) configurations.push_back(std::move(name));
  json imports = json::array();
  for (const auto& i : subsystem.remote_imports())
    imports.push_back(json{{"variable", i.variable},
                           {"stale", i.stale},
                           {"writer", i.writer},
                           {"samples", i.samples},
                           {"refused", i.refused},
                           {"age_ns", i.age_ns},
                           {"max_age_ns", i.max_age_ns},
                           {"refusal", i.refusal}});
  return json{{"subsystem", subsystem.spec().name},
              {"clock", subsystem.clock() == ClockKind::kVirtual ? "virtual" : "real"},
              {"now_ns", subsystem.now_ns()},
              {"configuration", subsystem.configuration()},
              {"configurations", std::move(configurations)},
              {"illegal_configuration", subsystem.illegal_configuration()},
              {"tasks", std::move(tasks)},
              {"imports", std::move(imports)}};
}

// The numbers of a `get` or `set` reply, "VAR = [1, 2.5]": read back from the very text the shell
// prints (fmt writes the shortest form that reads back exactly), so text and values agree.
std::optional<std::vector<double>> values_of(std::string_view text) {
  const auto open = text.find('[');
  const auto close = text.rfind(']');
  if (open == std::string_view::npos || close == std::string_view::npos || close < open) return std::nullopt;
  std::string_view list = text.substr(open + 1, close - open - 1);
  std::vector<double> values;
  while (!list.empty()) {
    while (!list.empty() && (list.front() == ' ' || list.front() == ',')) list.remove_prefix(1);
    if (list.empty()) break;
    double v = 0;
    const auto [ptr, ec] = std::from_chars(list.data(), list.data() + list.size(), v);
    if (ec != std::errc{}) return std::nullopt;
    values.push_back(v);
    list.remove_prefix(static_cast<std::size_t>(ptr - list.data()));
  }
  return values;
}

// A word of a command line: what parse_command() would read as one argument.
bool one_word(std::string_view word) {
  return !word.empty() && std::none_of(word.begin(), word.end(), [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
  });
}

// The body {"command": LINE} or {"verb": V, "args": [...]} as one command line; an error message
// otherwise.
std::variant<std::string, std::string> command_line(const json& doc) {
  using Out = std::variant<std::string, std::string>;
  auto fail = [](std::string message) { return Out(std::in_place_index<1>, std::move(message)); };
  if (!doc.is_object())
    return fail(R"(the body is a JSON object, {"command": "status"} or {"verb": "on", "args": ["pid"]})");
  for (const auto& [key, value] : doc.items())
    if (key != "command" && key != "verb" && key != "args")
      return fail(fmt::format("unknown key '{}' (command, or verb and args)", key));
  if (doc.contains("command")) {
    if (doc.contains("verb") || doc.contains("args")) return fail("give either command, or verb and args; not both");
    if (!doc["command"].is_string()) return fail("command: a string, e.g. \"on pid\"");
    return Out(std::in_place_index<0>, doc["command"].get<std::string>());
  }
  if (!doc.contains("verb")) return fail(R"(no command: {"command": "status"} or {"verb": "on", "args": ["pid"]})");
  if (!doc["verb"].is_string() || !one_word(doc["verb"].get_ref<const std::string&>()))
    return fail("verb: one word, e.g. \"status\"");
  std::string line = doc["verb"].get<std::string>();
  if (doc.contains("args")) {
    const json& args = doc["args"];
    if (!args.is_array()) return fail("args: an array of words and numbers");
    // add's one argument is a task entry: a JSON object is also a YAML flow mapping.
    if (line == "add" && args.size() == 1 && args[0].is_object())
      return Out(std::in_place_index<0>, "add " + dump(args[0]));
    for (std::size_t i = 0; i < args.size(); ++i) {
      const json& a = args[i];
      std::string word;
      if (a.is_string())
        word = a.get<std::string>();
      else if (a.is_number_integer())
        word = a.dump();
      else if (a.is_number_float())
        word = fmt::format("{}", a.get<double>());  // shortest form that reads back exactly
      else
        return fail(fmt::format("args[{}]: a word or a number", i));
      if (!one_word(word)) return fail(fmt::format("args[{}]: one word, without blanks", i));
      line += " " + word;
    }
  }
  return Out(std::in_place_index<0>, std::move(line));
}

// What the live assembly's verbs add to their reply, read right after the command.
void assembly_json(const Command& c, const Subsystem& subsystem, json& more) {
  switch (c.verb) {
    case Verb::kAdd: more["task"] = subsystem.spec().tasks.back().name; break;
    case Verb::kDefine:
    case Verb::kVerify: {
      auto violations = subsystem.verify_configuration(c.args.at(0));
      if (!violations) return;
      more["configuration"] = c.args.at(0);
      more["legal"] = violations->empty();
      more["violations"] = violations_json(*violations);
      break;
    }
    case Verb::kRemove: more["task"] = c.args.at(0); break;
    case Verb::kSave: {
      if (auto text = subsystem.save_yaml()) more["yaml"] = *text;
      break;
    }
    default: break;
  }
}

// `body` parsed into `doc`; or the 400 reply. A syntax error (parse_error) or a number too large
// for a double (out_of_range.406, thrown by the same parse): "[json.exception.parse_error.101]
// parse error at line 1, ...", of which the part after the tag is said.
std::optional<ApiResponse> parse_body(std::string_view body, json& doc) {
  try {
    doc = json::parse(body);
  } catch (const json::exception& e) {
    std::string_view what = e.what();
    if (const auto tag_end = what.find("] "); tag_end != std::string_view::npos) what.remove_prefix(tag_end + 2);
    return ControlApi::error(400, "bad_json", fmt::format("the body is not JSON: {}", what));
  }
  return std::nullopt;
}

// The paths of GET's documents (ControlApi::document), and the variables' below kVariables.
constexpr std::string_view kVariables = "/api/variables/";
constexpr std::array<std::string_view, 6> kDocuments{"/api/status",   "/api/whoami",  "/api/examples",
                                                     "/api/commands", "/api/modules", "/api/subsystem"};
bool is_document(std::string_view path) {
  return path.substr(0, kVariables.size()) == kVariables ||
         std::find(kDocuments.begin(), kDocuments.end(), path) != kDocuments.end();
}

}  // namespace

bool verb_needs_operator(Verb verb) {
  switch (verb) {
    case Verb::kStatus:
    case Verb::kStats:
    case Verb::kGet:
    case Verb::kHelp:
    case Verb::kVerify:
    case Verb::kSave: return false;  // save over the network only replies with the file
    default: return true;            // signals, switch, set, wait (time passes on the virtual clock), quit
  }
}

ControlApi::ControlApi(ControlGate& gate, AccessTokens tokens, std::function<void()> on_quit)
    : gate_(gate), tokens_(std::move(tokens)), on_quit_(std::move(on_quit)) {}

ApiResponse ControlApi::error(int status, std::string_view code, std::string_view message) {
  return ApiResponse{status, dump(json{{"ok", false}, {"error", {{"code", code}, {"message", message}}}}), {}};
}

ApiResponse ControlApi::too_large() {
  return error(413, "payload_too_large", fmt::format("the body is larger than {} bytes", kMaxBodyBytes));
}

void ControlApi::close() { closing_ = true; }

void ControlApi::sent(const ApiResponse& response) {
  if (response.stops_subsystem && on_quit_) on_quit_();
}

std::optional<Role> ControlApi::role_of(std::string_view authorization) const {
  return tokens_.role_of(bearer_token(authorization));
}

ApiResponse ControlApi::handle(const ApiRequest& request) {
  const std::optional<Role> role = role_of(request.authorization);
  if (!role) {
    return error(401, "unauthorized",
                 request.authorization.empty() ? "no token: send Authorization: Bearer TOKEN" : "wrong token");
  }
  if (closing_) return error(503, "closing", "the subsystem is stopping");
  if (request.body_too_large) return too_large();

  auto only = [&](std::string_view method) -> std::optional<ApiResponse> {
    if (request.method == method) return std::nullopt;
    ApiResponse r = error(405, "method_not_allowed", fmt::format("{} takes {} only", request.path, method));
    r.allow = std::string(method);
    return r;
  };
  const std::string_view path = request.path;
  if (path == "/api/command" || path == "/api/open") {
    if (auto refused = only("POST")) return *refused;
    if (request.body.size() > kMaxBodyBytes) return too_large();  // a transport that did not check
    return path == "/api/command" ? command(*role, request.body) : open(*role, request.body);
  }
  if (is_document(path)) {
    if (auto refused = only("GET")) return *refused;
    return document(*role, path);
  }
  return error(404, "not_found", fmt::format("no such endpoint: {} (see docs/control-api.md)", path));
}

ApiResponse ControlApi::document(Role role, std::string_view path) {
  if (path.substr(0, kVariables.size()) == kVariables) return variable(path.substr(kVariables.size()));
  if (path == "/api/status") return status();
  if (path == "/api/whoami") return reply(json{{"role", role_name(role)}});
  if (path == "/api/examples") return reply(json{{"examples", examples_json()}});
  if (path == "/api/commands") {
    json verbs = json::array();
    for (const auto& h : verb_help())
      verbs.push_back(json{{"verb", verb_name(h.verb)},
                           {"syntax", h.syntax},
                           {"does", h.does},
                           {"role", verb_needs_operator(h.verb) ? "operator" : "viewer"}});
    return reply(json{{"commands", std::move(verbs)}});
  }
  if (path == "/api/modules") {
    json modules = gate_.exclusive(
        [](Control& /*control*/, Subsystem& subsystem) { return module_library_json(subsystem.registry()); });
    return reply(json{{"modules", std::move(modules)}});
  }
  if (path == "/api/subsystem") {
    json model =
        gate_.exclusive([](Control& /*control*/, Subsystem& subsystem) { return subsystem_model_json(subsystem); });
    return reply(json{{"subsystem", std::move(model)}});
  }
  return error(404, "not_found", fmt::format("no such endpoint: {} (see docs/control-api.md)", path));
}

ApiResponse ControlApi::command(Role role, std::string_view body) {
  json doc;
  if (auto bad = parse_body(body, doc)) return *bad;
  auto line = command_line(doc);
  if (line.index() == 1) return error(400, "bad_request", std::get<1>(line));
  const std::string& text = std::get<0>(line);
  if (is_blank_or_comment(text)) return error(400, "bad_command", "empty command (try help)");
  auto parsed = parse_command(text);
  if (!parsed) return error(400, "bad_command", parsed.error().message);
  const Command& c = *parsed;
  const std::string_view verb = verb_name(c.verb);
  if (verb_needs_operator(c.verb) && role != Role::kOperator)
    return error(403, "forbidden", fmt::format("{}: needs an operator's token; this one is a viewer's", verb));
  if (c.verb == Verb::kWait) return wait(c);
  if (c.verb == Verb::kOpen)
    return error(400, "bad_command",
                 "open FILE reads the server's machine: over the network POST /api/open with the file's text");
  if (c.verb == Verb::kSave && !c.args.empty())
    return error(400, "bad_command",
                 "save FILE writes on the server's machine: over the network send save alone; the reply's yaml is the "
                 "file");

  if (c.verb == Verb::kDump && !c.args.empty())
    return error(400, "bad_command",
                 "dump DIR writes where DIR says on the server's machine: over the network send dump alone; it goes "
                 "below the run's dump directory (--dump-dir)");

  auto [r, extra] = gate_.exclusive([&](Control& control, Subsystem& subsystem) {
    Reply done = control.execute(c);
    json more = json::object();
    if (done.ok && c.verb == Verb::kStatus) more["status"] = status_json(subsystem);
    if (done.ok && (c.verb == Verb::kSwitch || c.verb == Verb::kStatus))
      more["configuration"] = subsystem.configuration();
    if (done.ok) assembly_json(c, subsystem, more);
    if (done.ok && c.verb == Verb::kStats) {
      const auto tasks = subsystem.snapshot();
      json all =
          json::parse(stats_json(tasks, subsystem.clock(), subsystem.switches().size(), false, JsonLayout::kCompact));
      if (!c.args.empty()) all["tasks"] = json{{c.args[0], all["tasks"][c.args[0]]}};
      more["stats"] = std::move(all);
    }
    return std::pair{std::move(done), std::move(more)};
  });

  extra["verb"] = verb;
  extra["text"] = r.text;
  if (!r.ok) {
    extra["ok"] = false;
    extra["error"] = json{{"code", "refused"}, {"message", last_line(r.text)}};
    return ApiResponse{409, dump(extra), {}};
  }
  if (c.verb == Verb::kGet || c.verb == Verb::kSet) {
    extra["variable"] = c.args.at(0);
    if (auto values = values_of(r.text)) extra["values"] = *values;
  }
  if (r.quit) extra["stopping"] = true;
  ApiResponse done = reply(std::move(extra));
  done.stops_subsystem = r.quit;
  return done;
}

ApiResponse ControlApi::open(Role role, std::string_view body) {
  if (role != Role::kOperator)
    return error(403, "forbidden", "open: needs an operator's token; this one is a viewer's");
  json doc;
  if (auto bad = parse_body(body, doc)) return *bad;
  constexpr std::string_view kShape = R"(the body is {"file": "fig4.yaml", "text": "the file's text"})";
  if (!doc.is_object() || !doc.contains("file") || !doc.contains("text") || !doc["file"].is_string() ||
      !doc["text"].is_string())
    return error(400, "bad_request", kShape);
  for (const auto& [key, value] : doc.items())
    if (key != "file" && key != "text")
      return error(400, "bad_request", fmt::format("unknown key '{}': {}", key, kShape));
  const std::string& name = doc["file"].get_ref<const std::string&>();

  std::optional<ApiResponse> refusal;
  auto [r, extra] = gate_.exclusive([&](Control& control, Subsystem& subsystem) {
    json more = json::object();
    auto path = opened_.write(name, doc["text"].get_ref<const std::string&>());
    if (!path) {
      refusal = error(path.error().code == Errc::kInvalidInput ? 400 : 500,
                      path.error().code == Errc::kInvalidInput ? "bad_request" : "system", path.error().message);
      return std::pair{Reply{}, std::move(more)};
    }
    Command c;
    c.verb = Verb::kOpen;
    c.args.push_back(*path);
    Reply done = control.execute(c);
    if (done.ok) {
      more["status"] = status_json(subsystem);
      more["configuration"] = subsystem.configuration();
    }
    return std::pair{std::move(done), std::move(more)};
  });
  if (refusal) return *refusal;
  extra["verb"] = "open";
  extra["file"] = name;
  extra["text"] = opened_.as_named(r.text);
  if (!r.ok) {
    extra["ok"] = false;
    extra["error"] = json{{"code", "refused"}, {"message", opened_.as_named(last_line(r.text))}};
    return ApiResponse{409, dump(extra), {}};
  }
  return reply(std::move(extra));
}

ApiResponse ControlApi::status() {
  json doc = gate_.exclusive([](Control& /*control*/, Subsystem& subsystem) { return status_json(subsystem); });
  return reply(json{{"status", std::move(doc)}});
}

ApiResponse ControlApi::variable(std::string_view name) {
  if (!one_word(name) || name.find('/') != std::string_view::npos)
    return error(404, "not_found", fmt::format("no state variable named '{}'", name));
  Command get;
  get.verb = Verb::kGet;
  get.args.emplace_back(name);
  const Reply r = gate_.execute(get);
  if (!r.ok) {
    // An unknown variable is a missing resource, as the path names it; one not written yet is not.
    const std::string_view why = last_line(r.text);
    return error(why.starts_with("no state variable") ? 404 : 409,
                 why.starts_with("no state variable") ? "not_found" : "refused", why);
  }
  json doc{{"verb", "get"}, {"text", r.text}, {"variable", name}};
  if (auto values = values_of(r.text)) doc["values"] = *values;
  return reply(std::move(doc));
}

ApiResponse ControlApi::wait(const Command& command) {
  if (command.duration_ns > kMaxWaitNs)
    return error(400, "bad_command", fmt::format("wait: at most {}s over the network", kMaxWaitNs / 1'000'000'000));
  const Reply r = gate_.execute(command);  // announces the wait; Control itself waits for nobody
  std::int64_t left = r.wait_ns;
  while (left > 0 && !closing_) {
    const std::int64_t step = std::min(left, ControlGate::kStepNs);
    gate_.run_for(step);
    left -= step;
  }
  if (left > 0) return error(503, "closing", "the subsystem is stopping");
  const std::int64_t now = gate_.exclusive([](Control& /*control*/, Subsystem& s) { return s.now_ns(); });
  return reply(json{{"verb", "wait"}, {"text", ""}, {"waited_ns", r.wait_ns}, {"now_ns", now}});
}

}  // namespace chimera::net
