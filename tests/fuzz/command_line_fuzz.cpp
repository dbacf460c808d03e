// Fuzz target: the shell's command parser (the words the shell, scripted input and the network
// API share). Any line parses to a command or to one line of refusal; a parsed command obeys the
// verb's arity, and `set`'s values and `wait`'s duration are what the parser promised.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "chimera/control/command.hpp"
#include "chimera/core/invariant.hpp"
#include "fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view line = chimera::fuzz::as_text(data, size);
  if (chimera::is_blank_or_comment(line)) return 0;
  auto command = chimera::parse_command(line);
  if (!command) {
    CHIMERA_INVARIANT(!command.error().message.empty(), "a refused command says nothing");
    return 0;
  }
  using chimera::Verb;
  CHIMERA_INVARIANT(!chimera::verb_name(command->verb).empty(), "a parsed verb has no name");
  if (command->verb == Verb::kSet) {
    CHIMERA_INVARIANT(command->values.size() + 1 == command->args.size(), "set: values and words differ");
    for (double v : command->values) CHIMERA_INVARIANT(std::isfinite(v), "set: a value is not finite");
  }
  if (command->verb == Verb::kWait) CHIMERA_INVARIANT(command->duration_ns >= 0, "wait: a negative duration");
  if (command->verb == Verb::kAdd) CHIMERA_INVARIANT(command->args.size() == 1, "add: not one entry");
  return 0;
}
