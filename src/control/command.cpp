#include "chimera/control/command.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"

namespace chimera {

namespace {

// How many words may follow each verb. kMany: no upper bound.
constexpr std::size_t kMany = std::numeric_limits<std::size_t>::max();

struct VerbSpec {
  Verb verb;
  std::string_view name;
  std::size_t min_args;
  std::size_t max_args;
  std::string_view syntax;
  std::string_view does;
};

// One table drives parsing, arity checks and `help`, so they cannot drift apart.
constexpr std::array kVerbs{
    VerbSpec{Verb::kStatus, "status", 0, 0, "status", "each task: lifecycle state, period, cycles, missed deadlines"},
    VerbSpec{Verb::kSpawn, "spawn", 1, 1, "spawn TASK", "create a task (init): NOT-CREATED -> OFF"},
    VerbSpec{Verb::kOn, "on", 1, kMany, "on TASK..", "activate tasks (on): OFF -> ON"},
    VerbSpec{Verb::kOff, "off", 1, kMany, "off TASK..", "deactivate tasks (off): ON -> OFF"},
    VerbSpec{Verb::kKill, "kill", 1, 1, "kill TASK", "destroy a task (off if ON, then kill): -> NOT-CREATED"},
    VerbSpec{Verb::kClear, "clear", 1, 1, "clear TASK", "the fault is fixed (clear): ERROR -> OFF"},
    VerbSpec{Verb::kSwitch, "switch", 1, 1, "switch CONFIG",
             "dynamic reconfiguration to another configuration of the file, at a cycle boundary"},
    VerbSpec{Verb::kGet, "get", 1, 1, "get VAR", "the current value of a state variable"},
    VerbSpec{Verb::kSet, "set", 2, kMany, "set VAR V..", "write a variable that no ON task produces"},
    VerbSpec{Verb::kWait, "wait", 1, 1, "wait DURATION", "let the subsystem run (e.g. 500ms) before the next command"},
    VerbSpec{Verb::kStats, "stats", 0, 1, "stats [TASK]", "the timing table, or one task's profile (histograms)"},
    VerbSpec{Verb::kQuit, "quit", 0, 0, "quit", "stop the subsystem cleanly (every task: off, then kill)"},
    VerbSpec{Verb::kHelp, "help", 0, 0, "help", "this list"},
    VerbSpec{Verb::kAdd, "add", 1, 1, "add {name: T, module: M, ...}",
             "add a task (NOT-CREATED), written as in the file's tasks:, while no task is created"},
    VerbSpec{Verb::kDefine, "define", 1, kMany, "define CONFIG TASK..",
             "define a configuration (new, or one that is not on) as these tasks"},
    VerbSpec{Verb::kVerify, "verify", 1, 1, "verify CONFIG",
             "check a configuration (eq. 1, eq. 2, sizes) without switching: what is missing or doubled"},
    VerbSpec{Verb::kRemove, "remove", 1, 1, "remove TASK", "remove a task that no configuration uses"},
    VerbSpec{Verb::kSave, "save", 0, 1, "save [FILE]",
             "the subsystem as a file that chimera verify accepts (to FILE, or as the reply)"},
    VerbSpec{Verb::kOpen, "open", 1, 1, "open FILE",
             "run another subsystem file instead (every task off and killed; its start configuration on)"},
    VerbSpec{Verb::kDump, "dump", 0, 1, "dump [DIR]",
             "write the flight recorder's last seconds of every variable and task's timing (to DIR, or a new one)"},
};

constexpr std::array<VerbHelp, kVerbs.size()> make_help() {
  std::array<VerbHelp, kVerbs.size()> out{};
  for (std::size_t i = 0; i < kVerbs.size(); ++i) out[i] = VerbHelp{kVerbs[i].verb, kVerbs[i].syntax, kVerbs[i].does};
  return out;
}
constexpr auto kHelp = make_help();

const VerbSpec* find_verb(std::string_view name) {
  for (const auto& v : kVerbs)
    if (v.name == name) return &v;
  return nullptr;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

std::vector<std::string> split_words(std::string_view line) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) words.emplace_back(line.substr(start, i - start));
  }
  return words;
}

std::optional<double> parse_number(std::string_view text) {
  // from_chars rejects a leading '+', which operators type; accept it here.
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc{} || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::string arity_message(const VerbSpec& v) {
  if (v.max_args == 0) return fmt::format("{} takes no arguments (usage: {})", v.name, v.syntax);
  if (v.min_args == v.max_args)
    return fmt::format("{} takes {} argument{} (usage: {})", v.name, v.min_args, v.min_args == 1 ? "" : "s", v.syntax);
  if (v.max_args != kMany)
    return fmt::format("{} takes at most {} argument{} (usage: {})", v.name, v.max_args, v.max_args == 1 ? "" : "s",
                       v.syntax);
  return fmt::format("{} takes at least {} argument{} (usage: {})", v.name, v.min_args, v.min_args == 1 ? "" : "s",
                     v.syntax);
}

}  // namespace

std::string_view verb_name(Verb verb) {
  for (const auto& v : kVerbs)
    if (v.verb == verb) return v.name;
  return "?";
}

std::span<const VerbHelp> verb_help() { return kHelp; }

bool is_blank_or_comment(std::string_view line) {
  for (char c : line) {
    if (is_space(c)) continue;
    return c == '#';
  }
  return true;
}

Result<Command> parse_command(std::string_view line) {
  auto words = split_words(line);
  if (words.empty()) return make_error(Errc::kInvalidInput, "empty command (try help)");
  const VerbSpec* spec = find_verb(words.front());
  if (spec == nullptr)
    return make_error(Errc::kInvalidInput, fmt::format("unknown command '{}' (try help)", words.front()));

  Command command;
  command.verb = spec->verb;
  if (command.verb == Verb::kAdd) {
    // The task entry is YAML, blanks and all: the rest of the line after the verb is one argument.
    std::string_view rest = line.substr(line.find(words.front()) + words.front().size());
    while (!rest.empty() && is_space(rest.front())) rest.remove_prefix(1);
    while (!rest.empty() && is_space(rest.back())) rest.remove_suffix(1);
    if (rest.empty()) return make_error(Errc::kInvalidInput, arity_message(*spec));
    command.args.emplace_back(rest);
    return command;
  }
  command.args.assign(std::make_move_iterator(words.begin() + 1), std::make_move_iterator(words.end()));
  if (command.args.size() < spec->min_args || command.args.size() > spec->max_args)
    return make_error(Errc::kInvalidInput, arity_message(*spec));

  if (command.verb == Verb::kSet) {
    for (std::size_t i = 1; i < command.args.size(); ++i) {
      const auto value = parse_number(command.args[i]);
      if (!value) return make_error(Errc::kInvalidInput, fmt::format("set: '{}' is not a number", command.args[i]));
      command.values.push_back(*value);
    }
  } else if (command.verb == Verb::kWait) {
    auto ns = parse_duration_ns(command.args.front());
    if (!ns) return make_error(Errc::kInvalidInput, fmt::format("wait: {}", ns.error().message));
    if (*ns < 0) return make_error(Errc::kInvalidInput, fmt::format("wait: '{}' is negative", command.args.front()));
    command.duration_ns = *ns;
  }
  return command;
}

}  // namespace chimera
