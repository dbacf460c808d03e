// The running subsystem: what it is made of, and the subsystem interface's operations on it. Each
// operation is the executive's or the reconfiguration's; this file only puts them in order and
// serialises them (ops_mutex): it chooses no clock.

#include "chimera/control/subsystem.hpp"

#include <unistd.h>

#include <array>
#include <mutex>
#include <shared_mutex>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/exec/write_watch.hpp"
#include "chimera/svt/global_table.hpp"
#include "chimera/svt/value_codec.hpp"
#include "exec/task_block.hpp"
#include "subsystem_impl.hpp"
#include "subsystem_test_access.hpp"

namespace chimera {

namespace {

std::string join_lines(const std::vector<Violation>& violations) {
  std::string out;
  for (const auto& v : violations) out += (out.empty() ? "" : "\n") + v.message;
  return out;
}

}  // namespace

Result<void> check_task_cpus(const SubsystemSpec& spec) {
  const long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
  for (const auto& t : spec.tasks)
    if (t.cpu && *t.cpu >= ncpu)
      return make_error(Errc::kInvalidInput, fmt::format("{}:{}: tasks.{}.cpu: cpu {} does not exist on this machine "
                                                         "({} CPUs)",
                                                         spec.file, t.loc.line, t.name, *t.cpu, ncpu));
  return {};
}

namespace {

// How the main process starts its module processes: the chimera binary in its worker mode, told
// the file, the table and the options of this run.
ProcessSetup process_setup(const SubsystemSpec& spec, const RunOptions& options, TaskBlock* block,
                           const FlightRecorder* recorder, const std::string& start) {
  ProcessSetup p;
  p.block = block;
  p.worker_program = options.worker_program;
  if (p.worker_program.empty()) {
    std::array<char, 4096> self{};
    const ssize_t n = ::readlink("/proc/self/exe", self.data(), self.size() - 1);
    p.worker_program = n > 0 ? std::string(self.data(), static_cast<std::size_t>(n)) : "chimera";
  }
  p.worker_args = {"--file", spec.file, "--table", spec.name + options.shm_suffix, "--config", start};
  if (!options.realtime_priorities) p.worker_args.emplace_back("--no-realtime");
  if (options.measure_cpu_time) p.worker_args.emplace_back("--cpu-time");
  if (options.rt_check) p.worker_args.emplace_back("--rt-check");
  if (recorder != nullptr) {
    // The length the main process laid its rings out for (shortened already, if it was): the
    // worker lays them out again from it, and maps the same block (fmt's shortest form reads back exactly).
    p.history_fd = recorder->shared_fd();
    p.worker_args.insert(p.worker_args.end(), {"--record-seconds", fmt::format("{}", recorder->seconds())});
  }
  return p;
}

}  // namespace

Result<void> Subsystem::Impl::build_runtime(const std::string& configuration, std::int64_t start_ns) {
  Impl& m = *this;
  const ConfigurationSpec* config = m.spec.find_configuration(configuration);
  if (config == nullptr)
    return make_error(Errc::kNotFound, fmt::format("{}: no configuration named '{}'", m.spec.file, configuration));
  Resolution fresh = resolve_subsystem(m.spec, *m.registry);
  auto violations = verify_subsystem(fresh, configuration);
  if (!violations.empty())
    return make_error(Errc::kIllegal, fmt::format("{}: configuration '{}' is not legal:\n{}", m.spec.file,
                                                  configuration, join_lines(violations)));

  // With module processes each variable has pages of its own, so that a worker can be let write
  // only its own tasks' (docs/processes.md).
  const bool processes = m.options.clock == ClockKind::kReal && m.spec.uses_module_processes();
  auto created =
      GlobalTable::create(m.spec.name + m.options.shm_suffix, fresh.subsystem.variables,
                          processes ? GlobalTable::Placement::kPagePerVariable : GlobalTable::Placement::kPacked);
  if (!created) return created.error();
  m.resolution = std::move(fresh);
  m.table = std::make_unique<GlobalTable>(std::move(*created));
  // Constants known up front (the file's and the out-consts modules declare) are in the table
  // before any init, so that an in-const reads its value whatever order tasks are spawned in.
  for (const auto& [name, values] : m.resolution.subsystem.constant_values) {
    if (auto v = m.table->find(name)) {
      auto bytes = encode_values(m.table->shape(*v), values);
      if (bytes) m.table->write(*v, bytes->data());
    }
  }

  const ResolvedSubsystem& resolved = m.resolution.subsystem;
  // Module processes run on the real clock only: the virtual clock simulates every task on one thread.
  std::vector<TaskShared*> shared;
  if (processes) {
    // A worker loads the subsystem from its file (docs/processes.md): text has none to read.
    if (::access(m.spec.file.c_str(), R_OK) != 0)
      return make_error(Errc::kInvalidInput, fmt::format("{}: module processes (process:) need the subsystem loaded "
                                                         "from a file their workers can read",
                                                         m.spec.file));
    auto made = TaskBlock::create(resolved.tasks.size());
    if (!made) return made.error();
    m.block = std::make_unique<TaskBlock>(std::move(*made));
    // Every task's shared part in the block, the main process's tasks' too: a producer in a module
    // process wakes an aperiodic task of the main process through it (TaskShared::wake).
    for (std::size_t i = 0; i < resolved.tasks.size(); ++i) shared.push_back(m.block->slot(i));
  }
  // With module processes the requests' slots and bell are the block's, where their tasks ask too.
  m.requests = m.block ? std::make_unique<SubsystemRequestBoard>(m.spec.configuration_names(), *m.block)
                       : std::make_unique<SubsystemRequestBoard>(m.spec.configuration_names(), resolved.tasks.size());
  m.tasks = std::make_unique<TaskSet>(resolved, *m.table, m.requests.get(), shared);
  m.events = std::make_unique<EventLog>(m.tasks->size());
  {
    std::lock_guard<std::mutex> notes(m.notes_mutex);
    m.error_ends.assign(m.tasks->size(), {});
    m.kill_faults.assign(m.tasks->size(), {});
    m.removed.assign(m.tasks->size(), false);
  }
  for (Task* t : m.tasks->pointers()) t->set_rt_check(m.options.rt_check);
  m.recorder = nullptr;
  if (m.options.record_seconds > 0) {
    // Shared when module processes run tasks: they write into the same rings (docs/processes.md).
    auto made = FlightRecorder::create(resolved, *m.table, *m.tasks, m.options.record_seconds,
                                       m.block ? FlightRecorder::Memory::kShared : FlightRecorder::Memory::kPrivate);
    if (!made) return made.error();
    m.recorder = std::move(*made);
  }
  m.dumped_failure.assign(m.tasks->size(), 0);
  ExecutiveSetup setup;
  setup.clock = m.options.clock;
  setup.realtime_priorities = m.options.realtime_priorities;
  setup.measure_cpu_time = m.options.measure_cpu_time;
  setup.subsystem = &resolved;
  setup.table = m.table.get();
  setup.tasks = m.tasks->pointers();
  setup.configuration = config->tasks;
  setup.events = m.events.get();
  setup.start_ns = start_ns;
  if (m.block) setup.processes = process_setup(m.spec, m.options, m.block.get(), m.recorder.get(), configuration);
  m.executive = make_executive(std::move(setup));
  for (const auto& [variable, watch] : m.watches)
    if (const auto v = m.table->find(variable)) m.executive->watch_writes(*v, watch.get());
  m.reconfiguration = std::make_unique<Reconfiguration>(resolved, configuration, *m.requests, *m.tasks, *m.executive,
                                                        *m.table, *m.events);
  m.runtimes_built.fetch_add(1, std::memory_order_release);  // release: the new table is there before the count says so
  return {};
}

std::uint64_t Subsystem::runtimes_built() const {
  return impl_->runtimes_built.load(std::memory_order_acquire);  // acquire: pairs with build_runtime()'s release
}

Subsystem::Subsystem() : impl_(std::make_unique<Impl>()) {}
Subsystem::~Subsystem() {
  stop();
  // A thread left behind by the stop may still run its module's code on these tasks, this
  // executive and the table: they are kept, reachable, for the rest of the process.
  if (!impl_->left_behind.empty()) {
    // Never freed, on purpose, and never destroyed at exit (the thread may still run then); a bad
    // allocation here ends the process, which is ending anyway.
    // NOLINTNEXTLINE(cppcoreguidelines-owning-memory,cppcoreguidelines-avoid-non-const-global-variables,bugprone-unhandled-exception-at-new)
    static auto* kept = new std::vector<std::unique_ptr<Impl>>();
    kept->push_back(std::move(impl_));
  }
}

Result<std::unique_ptr<Subsystem>> Subsystem::create(const SubsystemSpec& spec, const Registry& registry,
                                                     RunOptions options) {
  std::unique_ptr<Subsystem> s(new Subsystem());
  Impl& m = *s->impl_;
  m.spec = spec;
  m.options = std::move(options);
  const std::string start = m.options.configuration.value_or(m.spec.start);
  const ConfigurationSpec* start_config = m.spec.find_configuration(start);
  if (start_config == nullptr)
    return make_error(Errc::kNotFound, fmt::format("{}: no configuration named '{}'", spec.file, start));
  if (auto cpus = check_task_cpus(m.spec); !cpus) return cpus.error();
  m.registry = &registry;
  if (auto built = m.build_runtime(start, 0); !built) return built.error();
  return s;
}

Result<void> Subsystem::start() {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.ops_mutex);
    if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
    const ConfigurationSpec* config = m.spec.find_configuration(m.reconfiguration->configuration());
    std::vector<std::size_t> members;
    for (const auto& name : config->tasks) members.push_back(*m.tasks->index_of(name));
    auto abandon = [&](const Error& e) -> Result<void> {
      for (auto it = members.rbegin(); it != members.rend(); ++it)
        if ((*m.tasks)[*it].state() != TaskState::kNotCreated) (void)m.executive->signal(*it, Signal::kKill);
      m.events->collect(*m.tasks);
      return e;
    };
    for (const std::size_t i : members)
      if (auto r = m.executive->signal(i, Signal::kSpawn); !r) return abandon(r.error());
    if (auto r = m.executive->turn_on_together(members); !r) return abandon(r.error());
    m.events->collect(*m.tasks);
  }
  // From now on the switches tasks ask for are carried out (by a service thread on the real clock,
  // at the very instant on the virtual one), under the same lock as the operator's.
  serve_requests();
  return {};
}

void Subsystem::serve_requests() {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.ops_mutex);
    m.serving = true;
  }
  m.executive->serve(ServiceHooks{&m.requests->bell(), [this] {
                                    Impl& self = *impl_;
                                    std::lock_guard<std::mutex> lock(self.ops_mutex);
                                    if (!self.stopped) self.reconfiguration->serve_requests();
                                  }});
}

Result<void> Subsystem::signal(std::string_view task, Signal signal) {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
  const auto i = m.live_index(task);
  if (!i) return make_error(Errc::kNotFound, fmt::format("no task named '{}'", task));
  const bool was_in_error = (*m.tasks)[*i].state() == TaskState::kError;
  auto r = m.executive->signal(*i, signal);
  m.events->collect(*m.tasks);
  if (signal == Signal::kKill) m.note_kill(*i, r);
  if (was_in_error && (*m.tasks)[*i].state() != TaskState::kError) {
    const std::uint64_t failure = m.events->last_failure(*i).number;
    std::lock_guard<std::mutex> notes(m.notes_mutex);
    m.error_ends[*i] = Impl::ErrorEnd{failure, signal, m.executive->now_ns()};
  }
  return r;
}

void Subsystem::run_for(std::int64_t ns) {
  // No runtime lock: the live assembly's add, which replaces the executive, comes from the thread
  // that drives the commands, as this does (and the virtual clock's run_for takes ops_mutex).
  Impl& m = *impl_;
  if (m.stopped) return;
  m.executive->run_for(ns);
  if (m.recorder && !m.options.error_dump_dir.empty()) m.dump_new_errors();
}

Result<SwitchRecord> Subsystem::switch_to(std::string_view name, std::string_view cause) {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped) return make_error(Errc::kState, "the subsystem is stopped");
  return m.reconfiguration->switch_to(name, cause, m.executive->now_ns());
}

std::string Subsystem::configuration() const {
  std::lock_guard<std::mutex> lock(impl_->ops_mutex);
  return impl_->reconfiguration->configuration();
}

std::vector<SwitchRecord> Subsystem::switches(std::size_t first) const {
  std::lock_guard<std::mutex> lock(impl_->ops_mutex);
  const auto& history = impl_->reconfiguration->history();
  if (first >= history.size()) return {};
  return {history.begin() + static_cast<std::ptrdiff_t>(first), history.end()};
}

void Subsystem::stop() {
  Impl& m = *impl_;
  if (!m.executive) return;  // create() failed before it existed
  // The service thread takes ops_mutex to serve a request: stop it before taking the lock.
  m.executive->stop_serving();
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped) return;
  m.executive->begin_stop();  // a task stuck in a method delays the stop by a bound, not for ever
  m.off_then_kill_every_task();
  m.executive->shutdown();
  m.stopped = true;
  m.events->collect(*m.tasks);  // what off and kill reported stays readable, as do the tasks' figures
  std::unique_lock<std::shared_mutex> runtime(m.runtime_mutex);
  m.left_behind = m.executive->left_behind();
  if (m.left_behind.empty()) {
    m.table.reset();  // unlinks the shared memory
    return;
  }
  // A thread stuck in a method still runs and may touch the table: its mapping stays, only the
  // name goes (and with it the names of any other region of this process, which is about to end).
  // ~Subsystem keeps everything else that thread may touch.
  m.earlier_faults.push_back(fmt::format(
      "{} stuck in a method when the run stopped: {} thread was left behind, and the process ends without it",
      fmt::join(m.left_behind, ", "), m.left_behind.size() == 1 ? "its" : "their"));
  GlobalTable::remove_owned_names_now();
}

std::int64_t Subsystem::now_ns() const {
  std::shared_lock<std::shared_mutex> lock(impl_->runtime_mutex);  // an add replaces the executive
  return impl_->executive->now_ns();
}
ClockKind Subsystem::clock() const { return impl_->options.clock; }
const SubsystemSpec& Subsystem::spec() const { return impl_->spec; }
const ResolvedSubsystem& Subsystem::resolved() const { return impl_->resolution.subsystem; }
bool Subsystem::removed(std::size_t index) const {
  std::lock_guard<std::mutex> notes(impl_->notes_mutex);
  return index < impl_->removed.size() && impl_->removed[index];
}
const Registry& Subsystem::registry() const { return *impl_->registry; }

bool Subsystem::illegal_configuration() const {
  std::shared_lock<std::shared_mutex> lock(impl_->runtime_mutex);  // the table goes at stop
  return impl_->table && impl_->table->illegal_configuration();
}

void Subsystem::report_remote_imports(RemoteImportsReport report) { impl_->remote_imports = std::move(report); }

std::vector<RemoteImport> Subsystem::remote_imports() const {
  if (!impl_->remote_imports) return {};
  return impl_->remote_imports();
}

Result<void> Subsystem::watch_writes(const std::string& variable, std::shared_ptr<WriteWatch> watch) {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.ops_mutex);
  if (m.stopped || !m.table) return make_error(Errc::kState, "the subsystem is stopped");
  const auto v = m.table->find(variable);
  if (!v) return make_error(Errc::kNotFound, fmt::format("no state variable named '{}'", variable));
  m.executive->watch_writes(*v, watch.get());
  m.watches.emplace_back(variable, std::move(watch));  // kept until the Subsystem goes: tasks may ring it until stopped
  return {};
}

Result<std::vector<double>> Subsystem::get(std::string_view variable) const {
  const Impl& m = *impl_;
  std::shared_lock<std::shared_mutex> lock(m.runtime_mutex);  // the table goes at stop
  if (m.table == nullptr) return make_error(Errc::kState, "the subsystem is stopped");
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
  for (std::size_t i = 0; i < m.tasks->size(); ++i) {
    const Task& t = (*m.tasks)[i];
    if (t.state() != TaskState::kOn) continue;
    for (const auto& b : t.resolved().bindings)
      if (!is_input(b.kind) && b.variable == variable)
        return make_error(Errc::kState, fmt::format("{} is produced by task '{}', which is ON", variable, t.name()));
  }
  auto bytes = encode_values(m.table->shape(*v), values);
  if (!bytes) return bytes.error();
  m.table->write(*v, bytes->data());
  m.executive->variable_written(*v);
  return {};
}

std::vector<std::pair<std::string, TaskState>> Subsystem::states() const {
  const Impl& m = *impl_;
  std::shared_lock<std::shared_mutex> runtime(m.runtime_mutex);  // an add replaces the tasks
  std::vector<std::pair<std::string, TaskState>> out;
  out.reserve(m.tasks->size());
  for (std::size_t i = 0; i < m.tasks->size(); ++i)
    if (!m.is_removed(i)) out.emplace_back((*m.tasks)[i].name(), (*m.tasks)[i].state());
  return out;
}

std::vector<TaskSnapshot> Subsystem::snapshot() const {
  Impl& m = *impl_;
  std::shared_lock<std::shared_mutex> runtime(m.runtime_mutex);  // an add replaces the tasks
  m.events->collect(*m.tasks);  // so that last_error is current whether or not anyone drains events
  std::vector<TaskSnapshot> out;
  for (std::size_t i = 0; i < m.tasks->size(); ++i) {
    if (m.is_removed(i)) continue;
    const Task& t = (*m.tasks)[i];
    const TaskFailure failure = m.events->last_failure(i);
    TaskSnapshot snap;
    snap.name = t.name();
    snap.module = t.spec().module;
    snap.state = t.state();
    snap.period_ns = t.period_ns();
    snap.cpu = m.executive->cpu_of(i);
    snap.stats = t.stats().snapshot();
    snap.last_error = failure.text;
    snap.last_error_ns = failure.time_ns;
    {
      std::lock_guard<std::mutex> notes(m.notes_mutex);
      const Impl::ErrorEnd& end = m.error_ends[i];
      if (failure.number != 0 && end.failure == failure.number) {
        snap.error_ended_by = end.by;
        snap.error_ended_ns = end.at_ns;
      }
    }
    out.push_back(std::move(snap));
  }
  return out;
}

std::vector<Event> Subsystem::drain_events() {
  Impl& m = *impl_;
  std::shared_lock<std::shared_mutex> runtime(m.runtime_mutex);  // an add replaces the log
  m.events->collect(*m.tasks);                                   // the log's own lock makes it the rings' one consumer
  std::vector<Event> out;
  {
    std::lock_guard<std::mutex> notes(m.notes_mutex);
    out = std::exchange(m.earlier_events, {});
  }
  for (auto& e : m.events->drain()) out.push_back(std::move(e));
  return out;
}

GlobalTable& SubsystemTestAccess::table(Subsystem& subsystem) {
  CHIMERA_INVARIANT(subsystem.impl_->table != nullptr, "SubsystemTestAccess::table() after stop()");
  return *subsystem.impl_->table;
}

Executive& SubsystemTestAccess::executive(Subsystem& subsystem) {
  CHIMERA_INVARIANT(subsystem.impl_->executive != nullptr, "SubsystemTestAccess::executive() after stop()");
  return *subsystem.impl_->executive;
}

bool Subsystem::hard_task_failed() const {
  const Impl& m = *impl_;
  std::shared_lock<std::shared_mutex> runtime(m.runtime_mutex);
  return m.earlier_hard_failure || (m.tasks && m.tasks->hard_task_failed());
}

std::vector<std::string> Subsystem::faults() const {
  const Impl& m = *impl_;
  std::shared_lock<std::shared_mutex> runtime(m.runtime_mutex);
  std::vector<std::string> out = m.earlier_faults;
  for (auto& line : m.runtime_faults()) out.push_back(std::move(line));
  return out;
}

std::vector<std::string> Subsystem::Impl::runtime_faults() const {
  const Impl& m = *this;
  std::vector<std::string> out;
  if (!m.tasks) return out;
  m.events->collect(*m.tasks);
  for (std::size_t i = 0; i < m.tasks->size(); ++i) {
    const Task& t = (*m.tasks)[i];
    if (t.hard() && t.ever_in_error()) {
      const std::string last = m.events->last_error(i);
      out.push_back(last.empty() ? fmt::format("hard task {} entered ERROR", t.name())
                                 : fmt::format("hard task {} entered ERROR ({})", t.name(), last));
    }
    std::lock_guard<std::mutex> notes(m.notes_mutex);
    if (!m.kill_faults[i].empty()) out.push_back(fmt::format("task {}", m.kill_faults[i]));
  }
  return out;
}

}  // namespace chimera
