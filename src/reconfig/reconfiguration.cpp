// Dynamic reconfiguration (paper 3.4; docs/reconfiguration.md): the switch and the serving of the
// switches tasks ask for. reconfiguration.hpp says how.

#include "reconfiguration.hpp"

#include <algorithm>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/core/duration_text.hpp"
#include "chimera/svt/value_codec.hpp"
#include "switch_plan.hpp"

namespace chimera {

namespace {

// The values of the variables in `names`, as doubles, read from the table (missing: empty).
std::map<std::string, std::vector<double>> read_values(const GlobalTable& table,
                                                       const std::vector<std::string>& names) {
  std::map<std::string, std::vector<double>> out;
  for (const auto& name : names) {
    const auto v = table.find(name);
    if (!v) continue;
    std::vector<std::byte> bytes(table.shape(*v).bytes());
    if (table.read(*v, bytes.data(), 0).freshness == Freshness::kNoData) continue;
    out[name] = decode_values(table.shape(*v), bytes.data());
  }
  return out;
}

}  // namespace

std::string describe(const SwitchRecord& r) {
  std::string text = fmt::format("at {}: switch {} -> {} ({})", format_duration(r.committed_ns), r.from, r.to, r.cause);
  auto part = [&](const char* what, const std::vector<std::string>& names) {
    if (!names.empty()) text += fmt::format("{} {} {}", text.back() == ')' ? ":" : ";", what, fmt::join(names, ", "));
  };
  part("off", r.off);
  part("on", r.on);
  part("created", r.spawned);
  part("reinit", r.reinit);
  text += fmt::format("{} committed after {}", text.back() == ')' ? ":" : ";",
                      format_duration(r.committed_ns - r.requested_ns));
  if (r.flag_raised) text += ", illegal-configuration flag raised meanwhile";
  return text;
}

namespace {

// The names of the variables the out-consts of `indices` are bound to.
std::vector<std::string> const_outputs_of(const TaskSet& tasks, const std::vector<std::size_t>& indices) {
  std::vector<std::string> out;
  for (const std::size_t i : indices)
    for (auto& c : tasks[i].const_outputs()) out.push_back(std::move(c));
  return out;
}

std::vector<std::string> changed_values(const std::map<std::string, std::vector<double>>& before,
                                        const std::map<std::string, std::vector<double>>& after) {
  std::vector<std::string> changed;
  for (const auto& [var, value] : after) {
    const auto old = before.find(var);
    if (old == before.end() || old->second != value) changed.push_back(var);
  }
  return changed;
}

}  // namespace

Reconfiguration::Reconfiguration(const ResolvedSubsystem& subsystem, std::string start, SubsystemRequestBoard& requests,
                                 TaskSet& tasks, Executive& executive, GlobalTable& table, EventLog& events)
    : subsystem_(subsystem),
      requests_(requests),
      tasks_(tasks),
      executive_(executive),
      table_(table),
      events_(events),
      configuration_(std::move(start)),
      served_(tasks.size(), -1) {}

std::vector<std::string> Reconfiguration::names_of(const std::vector<std::size_t>& indices) const {
  std::vector<std::string> out;
  out.reserve(indices.size());
  for (const std::size_t i : indices) out.push_back(tasks_[i].name());
  return out;
}

Result<void> Reconfiguration::create_for_switch(const std::vector<std::size_t>& to_spawn) {
  std::vector<std::size_t> created;
  for (const std::size_t i : to_spawn) {
    tasks_[i].set_publish_at_spawn(false);  // the current configuration's producers are still ON
    auto r = executive_.signal(i, Signal::kSpawn);
    tasks_[i].set_publish_at_spawn(true);
    if (!r) {
      for (auto it = created.rbegin(); it != created.rend(); ++it) (void)executive_.signal(*it, Signal::kKill);
      return r;
    }
    created.push_back(i);
  }
  return {};
}

std::vector<std::string> Reconfiguration::reinit_readers(const std::vector<std::string>& changed,
                                                         const std::vector<std::size_t>& joining) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    const Task& t = tasks_[i];
    if (t.state() != TaskState::kOn) continue;
    if (std::find(joining.begin(), joining.end(), i) != joining.end()) continue;  // it read them at on()
    if (std::none_of(changed.begin(), changed.end(), [&](const std::string& v) { return t.reads_const(v); })) continue;
    names.push_back(t.name());
    (void)executive_.reinit(i);
  }
  return names;
}

Result<SwitchRecord> Reconfiguration::switch_to(std::string_view name, std::string_view cause,
                                                std::int64_t requested_ns) {
  const SubsystemSpec& spec = *subsystem_.spec;
  const ConfigurationSpec* target = spec.find_configuration(name);
  if (target == nullptr) {
    auto known = check_configuration_name(spec, name);
    return make_error(Errc::kNotFound, fmt::format("switch: {}", known.error().message));
  }
  if (target->name == configuration_)
    return make_error(Errc::kState, fmt::format("switch: configuration '{}' is already on", target->name));
  // Phase 1, prepare: verify, plan, create what is missing. Nothing has changed if this fails.
  auto violations = verify_tasks(subsystem_, target->tasks, target->name);
  if (!violations.empty()) return make_error(Errc::kIllegal, fmt::format("switch: {}", violations.front().message));
  std::vector<SwitchTask> states;
  for (std::size_t i = 0; i < tasks_.size(); ++i) states.push_back({tasks_[i].name(), tasks_[i].state()});
  auto plan = plan_switch(states, target->tasks);
  if (!plan)
    return make_error(plan.error().code, fmt::format("switch to '{}' refused: {}", name, plan.error().message));

  SwitchRecord record{configuration_,
                      target->name,
                      std::string(cause),
                      requested_ns,
                      0,
                      names_of(plan->leaving),
                      names_of(plan->joining),
                      names_of(plan->to_spawn),
                      {},
                      !plan->to_spawn.empty()};
  // The in-consts that may change value: the out-consts of the tasks leaving and joining, read
  // before any task is created (a new producer publishes its out-consts at on()).
  std::vector<std::string> consts = const_outputs_of(tasks_, plan->leaving);
  for (auto& c : const_outputs_of(tasks_, plan->joining)) consts.push_back(std::move(c));
  const auto before = read_values(table_, consts);

  // A switch that must create tasks takes longer than a cycle: the flag tells every module so,
  // and critical ones (the robot interfaces) hold still until the switch is over. The hold is
  // this switch's own, so nothing else lowers the flag meanwhile.
  std::optional<IllegalConfigurationHold> hold;
  if (record.flag_raised) hold.emplace(table_);
  if (auto created = create_for_switch(plan->to_spawn); !created) {
    events_.collect(tasks_);
    return make_error(created.error().code,
                      fmt::format("switch to '{}' refused: {}; nothing changed", name, created.error().message));
  }

  // Phase 2, commit at one cycle boundary; then consumers of a constant whose value changed read
  // it anew before their next cycle.
  const Result<void> committed =
      executive_.commit_switch(SwitchCommit{plan->leaving, plan->joining, record.flag_raised, target->tasks}).fault;
  record.committed_ns = executive_.now_ns();
  configuration_ = target->name;
  record.reinit = reinit_readers(changed_values(before, read_values(table_, consts)), plan->joining);
  hold.reset();

  requests_.clear();
  std::fill(served_.begin(), served_.end(), -1);
  events_.collect(tasks_);
  events_.add(Event{record.committed_ns, "", describe(record), true});
  history_.push_back(record);
  if (!committed)
    return make_error(committed.error().code,
                      fmt::format("{} (switched, with a fault: {})", describe(record), committed.error().message));
  return record;
}

void Reconfiguration::serve_requests() {
  const SubsystemSpec& spec = *subsystem_.spec;
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    const int asked = requests_.asked(i);
    if (asked < 0 || asked == served_[i]) continue;
    served_[i] = asked;
    const std::string& to = requests_.configuration_name(asked);
    if (to == configuration_) continue;  // asked for what is on: nothing to do
    const std::string& by = tasks_[i].name();
    if (spec.find_request(configuration_, to, by) == nullptr) {
      events_.add(Event{executive_.now_ns(), by,
                        fmt::format("asked for a switch to '{}' from '{}', which the file's requests: do not "
                                    "allow; refused",
                                    to, configuration_)});
      continue;
    }
    auto r = switch_to(to, fmt::format("requested by {}", by), executive_.now_ns());
    if (!r) events_.add(Event{executive_.now_ns(), by, r.error().message});
  }
}

}  // namespace chimera
