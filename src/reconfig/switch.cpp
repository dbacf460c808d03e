// Dynamic reconfiguration (paper 3.4; docs/reconfiguration.md): Subsystem::switch_to and the
// service that carries out the switches tasks ask for. Two phases, as STYLE asks: prepare and
// verify off the real-time path, where allocation and failure are allowed (plan, verify, create
// the missing tasks while the current configuration runs on); then commit at one cycle boundary
// in one step, which the executives carry out (leaving tasks off after their last release
// before it, joining tasks on and released from it, the others untouched).

#include <algorithm>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/control/timing_table.hpp"
#include "exec/subsystem_impl.hpp"
#include "exec/value_codec.hpp"
#include "switch_plan.hpp"

namespace chimera {

namespace {

constexpr std::int64_t kCommitMarginNs = 200'000;  // real clock: time to post the commit before it

std::vector<std::string> names_of(const std::vector<std::unique_ptr<Task>>& tasks, const std::vector<std::size_t>& is) {
  std::vector<std::string> out;
  out.reserve(is.size());
  for (const std::size_t i : is) out.push_back(tasks[i]->name());
  return out;
}

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

Result<SwitchRecord> Subsystem::switch_to(std::string_view name, std::string_view cause) {
  std::lock_guard<std::mutex> lock(impl_->ops_mutex);
  return switch_locked(name, cause, impl_->now());
}

std::string Subsystem::configuration() const {
  std::lock_guard<std::mutex> lock(impl_->ops_mutex);
  return impl_->configuration;
}

std::vector<SwitchRecord> Subsystem::switches() const {
  std::lock_guard<std::mutex> lock(impl_->ops_mutex);
  return impl_->history;
}

namespace {

// The names of the variables the out-consts of `indices` are bound to.
std::vector<std::string> const_outputs_of(const std::vector<std::unique_ptr<Task>>& tasks,
                                          const std::vector<std::size_t>& indices) {
  std::vector<std::string> out;
  for (const std::size_t i : indices)
    for (auto& c : tasks[i]->const_outputs()) out.push_back(std::move(c));
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

std::int64_t Subsystem::Impl::shortest_period(const std::vector<std::size_t>& a,
                                              const std::vector<std::size_t>& b) const {
  std::int64_t shortest = 0;
  for (const auto* list : {&a, &b})
    for (const std::size_t i : *list)
      if (tasks[i]->periodic() && (shortest == 0 || tasks[i]->period_ns() < shortest)) shortest = tasks[i]->period_ns();
  return shortest;
}

Result<void> Subsystem::Impl::create_for_switch(const std::vector<std::size_t>& to_spawn) {
  std::vector<std::size_t> created;
  for (const std::size_t i : to_spawn) {
    tasks[i]->set_publish_at_spawn(false);  // the current configuration's producers are still ON
    auto r = signal(i, Signal::kSpawn);
    tasks[i]->set_publish_at_spawn(true);
    if (!r) {
      for (auto it = created.rbegin(); it != created.rend(); ++it) (void)signal(*it, Signal::kKill);
      return r;
    }
    created.push_back(i);
  }
  return {};
}

Result<void> Subsystem::Impl::commit_switch(const std::vector<std::size_t>& leaving,
                                            const std::vector<std::size_t>& joining, bool created,
                                            const std::vector<std::string>& target) {
  const std::int64_t shortest = shortest_period(leaving, joining);
  plan = make_schedule_plan(resolution.subsystem, order, subsystem_cpus(spec), target);
  if (real_exec) {
    const std::int64_t now = real_exec->now_ns();
    const std::int64_t at = shortest > 0 ? ((now + kCommitMarginNs) / shortest + 1) * shortest : now;
    auto committed = real_exec->commit_switch(leaving, joining, at);
    real_exec->set_plan(plan);
    return committed;
  }
  // Creating tasks takes no simulated time, but a switch that must create them is one that takes
  // longer than a cycle: the old configuration runs on, flag raised, until the next boundary of
  // the fastest task involved.
  if (created && shortest > 0) (void)virtual_exec->run_until((virtual_exec->now_ns() / shortest + 1) * shortest);
  Result<void> committed;
  for (const std::size_t i : leaving) (void)signal(i, Signal::kOff);
  for (const std::size_t i : joining)
    if (auto r = signal(i, Signal::kOn); !r && committed) committed = r;
  virtual_exec->set_plan(plan);
  return committed;
}

std::vector<std::string> Subsystem::Impl::reinit_readers(const std::vector<std::string>& changed,
                                                         const std::vector<std::size_t>& joining) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const Task& t = *tasks[i];
    if (t.state() != TaskState::kOn) continue;
    if (std::find(joining.begin(), joining.end(), i) != joining.end()) continue;  // it read them at on()
    if (std::none_of(changed.begin(), changed.end(), [&](const std::string& v) { return t.reads_const(v); })) continue;
    names.push_back(t.name());
    (void)(virtual_exec ? virtual_exec->reinit(i) : real_exec->reinit(i));
  }
  return names;
}

Result<SwitchRecord> Subsystem::switch_locked(std::string_view name, std::string_view cause,
                                              std::int64_t requested_ns) {
  Impl& m = *impl_;
  if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
  const ConfigurationSpec* target = m.spec.find_configuration(name);
  if (target == nullptr) {
    auto known = check_configuration_name(m.spec, name);
    return make_error(Errc::kNotFound, fmt::format("switch: {}", known.error().message));
  }
  if (target->name == m.configuration)
    return make_error(Errc::kState, fmt::format("switch: configuration '{}' is already on", target->name));
  // Phase 1, prepare: verify, plan, create what is missing. Nothing has changed if this fails.
  auto violations = verify_tasks(m.resolution.subsystem, target->tasks, target->name);
  if (!violations.empty()) return make_error(Errc::kIllegal, fmt::format("switch: {}", violations.front().message));
  std::vector<SwitchTask> states;
  for (const auto& t : m.tasks) states.push_back({t->name(), t->state()});
  auto plan = plan_switch(states, target->tasks);
  if (!plan)
    return make_error(plan.error().code, fmt::format("switch to '{}' refused: {}", name, plan.error().message));

  SwitchRecord record{m.configuration,
                      target->name,
                      std::string(cause),
                      requested_ns,
                      0,
                      names_of(m.tasks, plan->leaving),
                      names_of(m.tasks, plan->joining),
                      names_of(m.tasks, plan->to_spawn),
                      {},
                      !plan->to_spawn.empty()};
  // The in-consts that may change value: the out-consts of the tasks leaving and joining, read
  // before any task is created (a new producer publishes its out-consts at on()).
  std::vector<std::string> consts = const_outputs_of(m.tasks, plan->leaving);
  for (auto& c : const_outputs_of(m.tasks, plan->joining)) consts.push_back(std::move(c));
  const auto before = read_values(*m.table, consts);

  // A switch that must create tasks takes longer than a cycle: the flag tells every module so,
  // and critical ones (the robot interfaces) hold still until it is lowered.
  m.switching_flag.store(record.flag_raised, std::memory_order_relaxed);  // relaxed: see Impl::switching_flag
  m.update_flag();
  if (auto created = m.create_for_switch(plan->to_spawn); !created) {
    m.switching_flag.store(false, std::memory_order_relaxed);  // relaxed: see Impl::switching_flag
    m.update_flag();
    m.collect_events();
    return make_error(created.error().code,
                      fmt::format("switch to '{}' refused: {}; nothing changed", name, created.error().message));
  }

  // Phase 2, commit at one cycle boundary; then consumers of a constant whose value changed read
  // it anew before their next cycle.
  const Result<void> committed = m.commit_switch(plan->leaving, plan->joining, record.flag_raised, target->tasks);
  record.committed_ns = m.now();
  m.configuration = target->name;
  record.reinit = m.reinit_readers(changed_values(before, read_values(*m.table, consts)), plan->joining);

  m.switching_flag.store(false, std::memory_order_relaxed);  // relaxed: see Impl::switching_flag
  m.update_flag();
  m.requests->clear();
  std::fill(m.served.begin(), m.served.end(), -1);
  m.collect_events();
  {
    std::lock_guard<std::mutex> events(m.events_mutex);
    m.pending.push_back(Event{record.committed_ns, "", describe(record)});
  }
  m.history.push_back(record);
  if (!committed)
    return make_error(committed.error().code,
                      fmt::format("{} (switched, with a fault: {})", describe(record), committed.error().message));
  return record;
}

void Subsystem::serve_requests() {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped) return;
  for (std::size_t i = 0; i < m.tasks.size(); ++i) {
    const int asked = m.requests->asked(i);
    if (asked < 0 || asked == m.served[i]) continue;
    m.served[i] = asked;
    const std::string& to = m.requests->configuration_name(asked);
    if (to == m.configuration) continue;  // asked for what is on: nothing to do
    const std::string& by = m.tasks[i]->name();
    if (m.spec.find_request(m.configuration, to, by) == nullptr) {
      std::lock_guard<std::mutex> events(m.events_mutex);
      m.pending.push_back(Event{m.now(), by,
                                fmt::format("asked for a switch to '{}' from '{}', which the file's requests: do not "
                                            "allow; refused",
                                            to, m.configuration)});
      continue;
    }
    auto r = switch_locked(to, fmt::format("requested by {}", by), m.now());
    if (!r) {
      std::lock_guard<std::mutex> events(m.events_mutex);
      m.pending.push_back(Event{m.now(), by, r.error().message});
    }
  }
}

}  // namespace chimera
