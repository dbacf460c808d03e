#include "chimera/exec/subsystem.hpp"

#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cstring>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "chimera/exec/clock.hpp"
#include "futex.hpp"
#include "subsystem_impl.hpp"
#include "value_codec.hpp"

namespace chimera {

namespace {
std::string join_lines(const std::vector<Violation>& violations) {
  std::string out;
  for (const auto& v : violations) out += (out.empty() ? "" : "\n") + v.message;
  return out;
}
}  // namespace

Subsystem::Subsystem() : impl_(std::make_unique<Impl>()) {}
Subsystem::~Subsystem() { stop(); }

Result<std::unique_ptr<Subsystem>> Subsystem::create(const SubsystemSpec& spec, const Registry& registry,
                                                     RunOptions options) {
  std::unique_ptr<Subsystem> s(new Subsystem());
  Impl& m = *s->impl_;
  m.spec = spec;  // the resolution below points into this copy, which never moves
  m.options = std::move(options);
  m.configuration = m.options.configuration.value_or(m.spec.start);
  if (m.spec.find_configuration(m.configuration) == nullptr)
    return make_error(Errc::kNotFound, fmt::format("{}: no configuration named '{}'", spec.file, m.configuration));
  const long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
  for (const auto& t : m.spec.tasks)
    if (t.cpu && *t.cpu >= ncpu)
      return make_error(Errc::kInvalidInput, fmt::format("{}:{}: tasks.{}.cpu: cpu {} does not exist on this machine "
                                                         "({} CPUs)",
                                                         spec.file, t.loc.line, t.name, *t.cpu, ncpu));

  m.resolution = resolve_subsystem(m.spec, registry);
  auto violations = verify_subsystem(m.resolution, m.configuration);
  if (!violations.empty())
    return make_error(Errc::kIllegal, fmt::format("{}: configuration '{}' is not legal:\n{}", spec.file,
                                                  m.configuration, join_lines(violations)));

  auto table = GlobalTable::create(m.spec.name + m.options.shm_suffix, m.resolution.subsystem.variables);
  if (!table) return table.error();
  m.table = std::make_unique<GlobalTable>(std::move(*table));
  m.flags = std::make_unique<detail::TableFlags>(m.table.get());
  // Constants known up front (the file's and the out-consts modules declare) are in the table
  // before any init, so that an in-const reads its value whatever order tasks are spawned in.
  for (const auto& [name, values] : m.resolution.subsystem.constant_values) {
    if (auto v = m.table->find(name)) {
      auto bytes = encode_values(m.table->shape(*v), values);
      if (bytes) m.table->write(*v, bytes->data());
    }
  }

  std::vector<std::string> configuration_names;
  for (const auto& c : m.spec.configurations) configuration_names.push_back(c.name);
  m.requests = std::make_unique<SubsystemRequestBoard>(configuration_names, m.resolution.subsystem.tasks.size());
  m.served.assign(m.resolution.subsystem.tasks.size(), -1);
  std::vector<Task*> raw;
  for (const auto& rt : m.resolution.subsystem.tasks) {
    m.tasks.push_back(std::make_unique<Task>(rt, *m.table, *m.flags));
    m.tasks.back()->set_request_board(m.requests.get(), static_cast<int>(raw.size()));
    raw.push_back(m.tasks.back().get());
  }
  m.last_error.assign(m.tasks.size(), {});
  m.order = compute_release_order(m.resolution.subsystem);
  const ConfigurationSpec* start_config = m.spec.find_configuration(m.configuration);
  m.plan = make_schedule_plan(m.resolution.subsystem, m.order, subsystem_cpus(m.spec), start_config->tasks);
  for (Task* t : raw) {
    t->set_virtual_clock(m.options.clock == ClockKind::kVirtual);
    if (m.options.measure_cpu_time || t->spec().wcet_ns) t->set_exec_clock(Task::ExecClock::kCpu);
  }
  if (m.options.clock == ClockKind::kVirtual) {
    m.virtual_exec = std::make_unique<VirtualExecutive>(raw, m.order, m.plan, *m.table);
  } else {
    prepare_realtime_process(m.options.realtime_priorities);
    m.real_exec = std::make_unique<RealExecutive>(raw, m.order, m.plan, m.options.realtime_priorities, *m.table);
  }
  return s;
}

Result<void> Subsystem::start() {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  const ConfigurationSpec* config = m.spec.find_configuration(m.configuration);
  std::vector<std::size_t> members;
  for (const auto& name : config->tasks) members.push_back(*m.index_of(name));
  auto abandon = [&](const Error& e) -> Result<void> {
    for (auto it = members.rbegin(); it != members.rend(); ++it)
      if (m.tasks[*it]->state() != TaskState::kNotCreated) (void)m.signal(*it, Signal::kKill);
    return e;
  };
  for (const std::size_t i : members)
    if (auto r = m.signal(i, Signal::kSpawn); !r) return abandon(r.error());
  // On together: no task runs a release before the others are on (the virtual clock does not
  // move while they turn on, so there one after the other is together).
  if (m.real_exec) {
    if (auto r = m.real_exec->turn_on_together(members); !r) return abandon(r.error());
  } else {
    for (const std::size_t i : members)
      if (auto r = m.signal(i, Signal::kOn); !r) return abandon(r.error());
  }
  m.collect_events();
  // Real clock: a thread of the subsystem interface carries out the switches tasks ask for (the
  // virtual clock does it in run_for, at the very instant they are asked for) and watches for
  // jobs overdue (a simulated job always ends).
  if (m.real_exec && !m.service.joinable()) {
    m.overdue_reported.assign(m.tasks.size(), -1);
    m.service = std::thread([this] {
      Impl& self = *impl_;
      std::uint32_t served = self.requests->changes().load(std::memory_order_acquire);  // acquire: the requests
      serve_requests();
      std::int64_t next_watch = monotonic_ns() + Impl::kWatchTickNs;
      for (;;) {
        if (self.service_stop.load(std::memory_order_acquire)) return;  // acquire: pairs with stop()
        const std::uint32_t now = self.requests->changes().load(std::memory_order_acquire);  // acquire: as above
        if (now != served) {
          served = now;
          serve_requests();
        }
        if (monotonic_ns() >= next_watch) {
          self.watch_overruns();
          next_watch += Impl::kWatchTickNs;
        }
        (void)detail::futex_wait(self.requests->changes(), served, next_watch);
      }
    });
  }
  return {};
}

Result<void> Subsystem::signal(std::string_view task, Signal signal) {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
  const auto i = m.index_of(task);
  if (!i) return make_error(Errc::kNotFound, fmt::format("no task named '{}'", task));
  auto r = m.signal(*i, signal);
  m.collect_events();
  m.update_flag();  // a task cleared or killed out of ERROR may lower the flag
  return r;
}

void Subsystem::run_for(std::int64_t ns) {
  Impl& m = *impl_;
  if (ns <= 0 || m.stopped) return;
  if (m.virtual_exec) {
    const std::int64_t end = m.virtual_exec->now_ns() + ns;
    // A task that asks for a switch stops the simulation at that instant; the switch happens
    // there, and the run goes on: the same file and inputs give the same trace.
    while (!m.virtual_exec->run_until(end, &m.requests->changes())) serve_requests();
  } else {
    std::this_thread::sleep_for(std::chrono::nanoseconds(ns));
  }
}

void Subsystem::stop() {
  Impl& m = *impl_;
  if (m.service.joinable()) {
    m.service_stop.store(true, std::memory_order_release);  // release: the service sees it after its wake
    m.requests->wake();
    m.service.join();
  }
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped || !m.table) return;
  // The paper's two-step termination: every task off, then every task killed.
  for (std::size_t i = 0; i < m.tasks.size(); ++i)
    if (m.tasks[i]->state() == TaskState::kOn) (void)m.signal(i, Signal::kOff);
  for (std::size_t i = 0; i < m.tasks.size(); ++i)
    if (m.tasks[i]->state() != TaskState::kNotCreated) (void)m.signal(i, Signal::kKill);
  m.stopped_at_ns = m.now();
  m.stopped = true;
  m.real_exec.reset();  // joins the threads
  m.virtual_exec.reset();
  m.collect_events();  // what off and kill reported stays readable, as do the tasks' figures
  m.table.reset();     // unlinks the shared memory
}

std::int64_t Subsystem::now_ns() const { return impl_->now(); }
ClockKind Subsystem::clock() const { return impl_->options.clock; }
const SubsystemSpec& Subsystem::spec() const { return impl_->spec; }
const ResolvedSubsystem& Subsystem::resolved() const { return impl_->resolution.subsystem; }
GlobalTable& Subsystem::table() {
  assert(impl_->table && "table() after stop()");
  return *impl_->table;
}

Result<std::vector<double>> Subsystem::get(std::string_view variable) const {
  const Impl& m = *impl_;
  if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
  const auto v = m.table->find(variable);
  if (!v) return make_error(Errc::kNotFound, fmt::format("no state variable named '{}'", variable));
  std::vector<std::byte> bytes(m.table->shape(*v).bytes());
  const ReadOutcome r = m.table->read(*v, bytes.data(), 0);
  if (r.freshness == Freshness::kNoData)
    return make_error(Errc::kNotFound, fmt::format("{} has not been written yet", variable));
  return decode_values(m.table->shape(*v), bytes.data());
}

Result<void> Subsystem::set(std::string_view variable, const std::vector<double>& values) {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);  // no switch may turn a producer on meanwhile
  if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
  const auto v = m.table->find(variable);
  if (!v) return make_error(Errc::kNotFound, fmt::format("no state variable named '{}'", variable));
  for (const auto& [name, value] : m.spec.constants)
    if (name == variable) return make_error(Errc::kState, fmt::format("{} is a subsystem constant", variable));
  for (const auto& t : m.tasks) {
    if (t->state() != TaskState::kOn) continue;
    for (const auto& b : t->resolved().bindings)
      if (!is_input(b.kind) && b.variable == variable)
        return make_error(Errc::kState, fmt::format("{} is produced by task '{}', which is ON", variable, t->name()));
  }
  auto bytes = encode_values(m.table->shape(*v), values);
  if (!bytes) return bytes.error();
  m.table->write(*v, bytes->data());
  if (m.real_exec) m.real_exec->variable_written(*v);  // the virtual clock sees the new version itself
  return {};
}

std::vector<TaskSnapshot> Subsystem::snapshot() const {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> ops(m.ops_mutex);  // the plan changes at a switch
  m.collect_events();                            // so that last_error is current whether or not anyone drains events
  std::lock_guard<std::mutex> lock(m.events_mutex);
  std::vector<TaskSnapshot> out;
  for (std::size_t i = 0; i < m.tasks.size(); ++i) {
    const Task& t = *m.tasks[i];
    out.push_back(TaskSnapshot{t.name(), t.spec().module, t.state(), t.period_ns(), m.plan.cpu[i], t.stats().snapshot(),
                               m.last_error[i]});
  }
  return out;
}

std::vector<Event> Subsystem::drain_events() {
  Impl& m = *impl_;
  m.collect_events();
  std::lock_guard<std::mutex> lock(m.events_mutex);
  std::vector<Event> out = std::move(m.pending);
  m.pending.clear();
  std::stable_sort(out.begin(), out.end(), [](const Event& a, const Event& b) { return a.time_ns < b.time_ns; });
  return out;
}

bool Subsystem::hard_task_failed() const {
  for (const auto& t : impl_->tasks)
    if (t->hard() && t->ever_in_error()) return true;
  return false;
}

}  // namespace chimera
