#pragma once
// The operator's commands (contract section 2, "The shell"), parsed once from a line of text so
// that the shell, the CLI's scripted input and the network API all accept exactly the same words.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/core/result.hpp"

namespace chimera {

enum class Verb {
  kStatus,
  kSpawn,
  kOn,
  kOff,
  kKill,
  kClear,
  kSwitch,
  kGet,
  kSet,
  kWait,
  kStats,
  kQuit,
  kHelp,
  // The live assembly (docs/control-api.md, "Live assembly").
  kAdd,
  kDefine,
  kVerify,
  kRemove,
  kSave,
  kOpen,
  // The flight recorder (docs/flight-recorder.md).
  kDump,
};

/// The word that names `verb` on the command line ("status", "on", ...).
std::string_view verb_name(Verb verb);

/// One parsed command. `args` are the words after the verb (for `add`, the one task entry: the
/// rest of the line, blanks and all); for `set` the numbers are also in
/// `values`, for `wait` the duration is in `duration_ns`, so nobody parses them twice.
struct Command {
  Verb verb = Verb::kHelp;
  std::vector<std::string> args;
  std::vector<double> values;
  std::int64_t duration_ns = 0;
};

/// Splits `line` at whitespace and checks the verb, the number of arguments, the numbers of
/// `set` and the duration of `wait`. Errors (Errc::kInvalidInput) are one line for the operator,
/// e.g. "unknown command 'x' (try help)". Not real-time safe.
Result<Command> parse_command(std::string_view line);

/// True for a line that carries no command: empty, only blanks, or a comment starting with '#'.
bool is_blank_or_comment(std::string_view line);

/// One line per command: its syntax and what it does. For `help`.
struct VerbHelp {
  Verb verb;
  std::string_view syntax;
  std::string_view does;
};
std::span<const VerbHelp> verb_help();

}  // namespace chimera
