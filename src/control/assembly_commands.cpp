// The live assembly's verbs of the command API: add, define, verify, remove, save and open, each one
// call of the Subsystem's live assembly and the words the shell prints for it.

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/control.hpp"
#include "reply_text.hpp"

namespace chimera {

namespace {

using control_detail::refused;
using control_detail::said;

// The violations of one configuration as one line: "legal", or each reason in turn.
std::string verdict(const std::vector<Violation>& violations) {
  if (violations.empty()) return "legal";
  std::vector<std::string> reasons;
  reasons.reserve(violations.size());
  for (const auto& v : violations) reasons.push_back(violation_reason(v));
  return fmt::format("not legal: {}", fmt::join(reasons, "; "));
}

// Writes `text` to `path` whole or not at all: a temporary file beside it, renamed over it.
Result<void> write_whole(const std::string& path, const std::string& text) {
  const std::string temporary = fmt::format("{}.{}.tmp", path, ::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      std::remove(temporary.c_str());
      return make_error(Errc::kSystem, fmt::format("save: cannot write {}", path));
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    std::remove(temporary.c_str());
    return make_error(Errc::kSystem,
                      fmt::format("save: cannot write {}: {}", path, std::generic_category().message(error)));
  }
  return {};
}

}  // namespace

std::string violation_reason(const Violation& violation) {
  const std::string tasks = fmt::format("{}", fmt::join(violation.tasks, ", "));
  switch (violation.rule) {
    case 1: return fmt::format("{} has more than one producer ({})", violation.variable, tasks);
    case 2: return fmt::format("{} has no producer (read by {})", violation.variable, tasks);
    default: break;
  }
  // Rule 3 and names that do not exist: verification's own words, without the configuration.
  std::string_view text = violation.message;
  const std::string prefix = fmt::format("configuration '{}': ", violation.configuration);
  if (text.starts_with(prefix)) text.remove_prefix(prefix.size());
  return std::string(text);
}

Reply Control::assemble(const Command& command) {
  switch (command.verb) {
    case Verb::kAdd: return add(command.args.at(0));
    case Verb::kDefine: return define(command.args);
    case Verb::kVerify: return verify(command.args.at(0));
    case Verb::kRemove: return remove(command.args.at(0));
    case Verb::kSave: return save(command.args);
    case Verb::kOpen: return open(command.args.at(0));
    default: return refused(fmt::format("{}: not a live assembly command", verb_name(command.verb)));
  }
}

Reply Control::add(const std::string& entry) {
  auto added = subsystem_.add_task(entry);
  if (!added) return refused(added.error().message);
  return said(fmt::format("{}: NOT-CREATED (added)\n", *added));
}

Reply Control::define(const std::vector<std::string>& args) {
  const std::string& name = args.at(0);
  const std::vector<std::string> tasks(args.begin() + 1, args.end());
  if (auto defined = subsystem_.define_configuration(name, tasks); !defined) return refused(defined.error().message);
  auto violations = subsystem_.verify_configuration(name);
  if (!violations) return refused(violations.error().message);
  return said(fmt::format("configuration '{}': [{}] ({})\n", name, fmt::join(tasks, ", "), verdict(*violations)));
}

Reply Control::verify(const std::string& configuration) const {
  auto violations = subsystem_.verify_configuration(configuration);
  if (!violations) return refused(violations.error().message);
  std::string text = fmt::format("configuration '{}' is {}\n", configuration, verdict(*violations));
  for (const auto& v : *violations) text += fmt::format("  {}\n", v.message);
  return said(std::move(text));
}

Reply Control::remove(const std::string& task) {
  if (auto removed = subsystem_.remove_task(task); !removed) return refused(removed.error().message);
  return said(fmt::format("{}: removed\n", task));
}

Reply Control::save(const std::vector<std::string>& args) const {
  auto text = subsystem_.save_yaml();
  if (!text) return refused(text.error().message);
  if (args.empty()) return said(*std::move(text));
  if (auto written = write_whole(args.front(), *text); !written) return refused(written.error().message);
  return said(fmt::format("saved to {}\n", args.front()));
}

Reply Control::open(const std::string& file) {
  // The modules the subsystem has: a file's plugins: are loaded by chimera run FILE, not here.
  auto spec = load_subsystem_file(file, subsystem_.registry());
  if (!spec) return refused(spec.error().message);
  if (auto replaced = subsystem_.replace(*std::move(spec)); !replaced) return refused(replaced.error().message);
  std::vector<std::string> states;
  for (const auto& [task, state] : subsystem_.states())
    states.push_back(fmt::format("{}: {}", task, state_name(state)));
  return said(fmt::format("opened {}: subsystem {}, configuration '{}' on ({})\n", file, subsystem_.spec().name,
                          subsystem_.configuration(), fmt::join(states, ", ")));
}

}  // namespace chimera
