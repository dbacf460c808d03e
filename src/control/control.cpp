#include "chimera/control/control.hpp"

#include <algorithm>
#include <exception>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/control/remote_imports.hpp"
#include "chimera/control/task_profile.hpp"
#include "chimera/control/timing_table.hpp"
#include "reply_text.hpp"

namespace chimera {

namespace {

using control_detail::refused;
using control_detail::said;

std::string format_values(std::string_view variable, const std::vector<double>& values) {
  return fmt::format("{} = [{}]\n", variable, fmt::join(values, ", "));
}

std::string help_text() {
  std::size_t width = 0;
  for (const auto& h : verb_help()) width = std::max(width, h.syntax.size());
  std::string out;
  for (const auto& h : verb_help()) out += fmt::format("  {:<{}}  {}\n", h.syntax, width, h.does);
  return out;
}

Signal signal_of(Verb verb) {
  switch (verb) {
    case Verb::kSpawn: return Signal::kSpawn;
    case Verb::kOn: return Signal::kOn;
    case Verb::kOff: return Signal::kOff;
    case Verb::kKill: return Signal::kKill;
    default: return Signal::kClear;
  }
}

}  // namespace

std::string_view required_state_text(Signal signal) {
  switch (signal) {
    case Signal::kSpawn: return "NOT-CREATED";
    case Signal::kOn: return "OFF";
    case Signal::kOff: return "ON";
    case Signal::kKill: return "OFF, ON or ERROR";
    case Signal::kClear: return "ERROR";
  }
  return "?";
}

Reply Control::execute(const Command& command) {
  // A fault inside the Subsystem must not take the shell down with it; the operator reads it.
  try {
    switch (command.verb) {
      case Verb::kStatus: {
        std::string text = status_table(subsystem_.snapshot());
        // The variables other subsystems feed (docs/dds.md): whether each is fresh, and from whom.
        if (const auto imports = subsystem_.remote_imports(); !imports.empty())
          text += "\n" + remote_imports_table(imports);
        // The flag is what makes the robot interfaces hold the arm (paper 3.4): say when it is up.
        if (subsystem_.illegal_configuration())
          text += "illegal-configuration flag raised: the robot interfaces hold the arm\n";
        return said(std::move(text));
      }
      case Verb::kStats: {
        const auto tasks = subsystem_.snapshot();
        if (command.args.empty()) return said(timing_table(tasks));
        for (const auto& t : tasks)
          if (t.name == command.args[0]) return said(task_profile(t));
        return refused(fmt::format("unknown task '{}'", command.args[0]));
      }
      case Verb::kSpawn:
      case Verb::kOn:
      case Verb::kOff:
      case Verb::kKill:
      case Verb::kClear: return signal_tasks(signal_of(command.verb), command.args);
      case Verb::kSwitch: {
        auto record = subsystem_.switch_to(command.args.at(0));
        if (!record) return refused(record.error().message);
        return said(describe(*record) + "\n");
      }
      case Verb::kGet: return get(command.args.at(0));
      case Verb::kSet: return set(command.args.at(0), command.values);
      case Verb::kWait: {
        Reply r;
        r.wait_ns = command.duration_ns;
        return r;
      }
      case Verb::kQuit: {
        Reply r;
        r.quit = true;
        return r;
      }
      case Verb::kHelp: return said(help_text());
      case Verb::kAdd:
      case Verb::kDefine:
      case Verb::kVerify:
      case Verb::kRemove:
      case Verb::kSave:
      case Verb::kOpen: return assemble(command);
      case Verb::kDump: {
        auto written = subsystem_.dump(command.args.empty() ? std::string() : command.args[0], "the operator's dump");
        if (!written) return refused(written.error().message);
        return said(fmt::format("the last {:.3g} s written to {}/\n", subsystem_.recorded_seconds(), *written));
      }
    }
  } catch (const std::exception& e) {
    return refused(fmt::format("{}: internal error: {}", verb_name(command.verb), e.what()));
  }
  return refused("unknown command (try help)");
}

Reply Control::execute_line(std::string_view line) {
  if (is_blank_or_comment(line)) return {};
  auto command = parse_command(line);
  if (!command) return refused(command.error().message);
  return execute(*command);
}

Reply Control::signal_tasks(Signal signal, const std::vector<std::string>& names) {
  const std::string_view verb = signal_name(signal);
  const auto tasks = subsystem_.snapshot();
  auto find = [&](std::string_view name) -> const TaskSnapshot* {
    auto it = std::find_if(tasks.begin(), tasks.end(), [&](const TaskSnapshot& t) { return t.name == name; });
    return it == tasks.end() ? nullptr : &*it;
  };

  // Check every name and every transition before sending anything, so that a refused command
  // leaves all tasks as they were.
  // Names first: a typo is the likelier mistake and the more useful thing to hear about.
  std::vector<const TaskSnapshot*> targets;
  for (const auto& name : names) {
    const TaskSnapshot* task = find(name);
    if (task == nullptr) return refused(fmt::format("unknown task '{}'", name));
    if (std::find(targets.begin(), targets.end(), task) == targets.end()) targets.push_back(task);  // listed twice
  }
  for (const TaskSnapshot* task : targets)
    if (!transition(task->state, signal))
      return refused(fmt::format("{} {}: task is {}, {} needs {}", verb, task->name, state_name(task->state), verb,
                                 required_state_text(signal)));

  Reply reply;
  std::vector<std::string> done;
  for (const TaskSnapshot* task : targets) {
    auto sent = subsystem_.signal(task->name, signal);
    if (!sent) {
      reply.ok = false;
      reply.text = sent.error().message + "\n";
      break;
    }
    done.push_back(task->name);
  }
  // Report the states the tasks really reached; a method may have failed on the way.
  const auto after = subsystem_.snapshot();
  std::string lines;
  for (const auto& name : done) {
    auto it = std::find_if(after.begin(), after.end(), [&](const TaskSnapshot& t) { return t.name == name; });
    if (it != after.end()) lines += fmt::format("{}: {}\n", name, state_name(it->state));
  }
  reply.text = lines + reply.text;
  return reply;
}

Reply Control::get(const std::string& variable) const {
  auto values = subsystem_.get(variable);
  if (!values) return refused(values.error().message);
  return said(format_values(variable, *values));
}

Reply Control::set(const std::string& variable, const std::vector<double>& values) {
  auto written = subsystem_.set(variable, values);
  if (!written) return refused(written.error().message);
  return said(format_values(variable, values));
}

std::string Control::drain_events() { return event_lines(subsystem_.drain_events()); }

std::string event_lines(const std::vector<Event>& events) {
  std::string out;
  for (const auto& e : events) {
    std::string_view text = e.text;
    while (!text.empty() && (text.back() == ' ' || text.back() == '\n')) text.remove_suffix(1);
    if (e.task.empty())
      out += fmt::format("{}\n", text);
    else
      out += fmt::format("{}: {}\n", e.task, text);
  }
  return out;
}

}  // namespace chimera
