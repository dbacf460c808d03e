#include "task.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <ctime>
#include <exception>
#include <limits>

#include <fmt/format.h>

#include "chimera/exec/clock.hpp"
#include "rt_check_scope.hpp"

namespace chimera {

namespace {
const char* hook_name(std::uint8_t hook) {
  static constexpr std::array<const char*, 8> kNames = {"on",    "cycle", "off",    "kill",
                                                        "error", "clear", "reinit", "sync"};
  return kNames[hook];
}

// "file:line: key: init failed: why", at the parameter init refused if it named one, else at the
// task; as the loader's messages read, so that every refusal of a file points into it.
std::string init_failure_message(const TaskSpec& spec, const std::string& param, const std::string& reason) {
  const SourceLoc at = param.empty() ? spec.loc : spec.loc_of_param(param);
  const std::string key = param.empty() ? spec.name : fmt::format("{}.params.{}", spec.name, param);
  if (at.file.empty() || at.line <= 0) return fmt::format("{}: init failed: {}", key, reason);
  return fmt::format("{}:{}: {}: init failed: {}", at.file, at.line, key, reason);
}
}  // namespace

const char* busy_in_name(BusyIn method) noexcept {
  static constexpr std::array<const char*, 8> kNames = {"init", "on",    "cycle",  "off",
                                                        "kill", "clear", "reinit", "error"};
  return kNames[static_cast<std::size_t>(method)];
}

Task::Task(const ResolvedTask& resolved, GlobalTable& table, const SubsystemFlags& flags, TaskShared* shared)
    : spec_(*resolved.spec),
      resolved_(resolved),
      table_(table),
      flags_(flags),
      own_shared_(shared == nullptr ? std::make_unique<TaskShared>() : nullptr),
      shared_(shared == nullptr ? own_shared_.get() : shared) {
  timing_.period_ns = spec_.period_ns.value_or(0);
}

Task::~Task() {
  // A destructor must not throw: the kill's message (a std::string) could fail to allocate.
  try {
    // A view of a task run by another process has no module here: that process kills it.
    if (module_ != nullptr && state() != TaskState::kNotCreated) (void)apply(Signal::kKill, timing_.release_ns);
  } catch (...) {
    destroy_module();
  }
}

Status Task::call_raw(Hook hook) noexcept {
  // The methods the template says must not allocate; init, kill, reinit, error and clear may.
  const bool real_time = hook == Hook::kOn || hook == Hook::kCycle || hook == Hook::kOff || hook == Hook::kSync;
  if (!rt_check_ || !real_time) return dispatch(hook);
  rt_hook_ = hook;
  const RtCheckScope scope(*this);
  return dispatch(hook);
}

void Task::note_rt_allocation() noexcept {
  // Once per task: a cycle that allocates does so every cycle, and the count tells the rest.
  if (shared_->stats.record_rt_allocation())
    shared_->events.push(timing_.release_ns, hook_name(static_cast<std::uint8_t>(rt_hook_)),
                         "() allocated on the real-time path (--rt-check)");
}

void Task::keep_history(HistoryRings* rings, std::int32_t timing_ring,
                        std::span<const std::int32_t> ring_of_var) noexcept {
  history_ = timing_ring >= 0 ? rings : nullptr;
  timing_ring_ = timing_ring;
  ring_of_var_ = ring_of_var;
  if (local_) local_->keep_history(history_, ring_of_var_);
}

Status Task::dispatch(Hook hook) noexcept {
  try {
    switch (hook) {
      case Hook::kOn: return module_->on();
      case Hook::kCycle: return module_->cycle();
      case Hook::kOff: return module_->off();
      case Hook::kKill: return module_->kill();
      case Hook::kError: return module_->error();
      case Hook::kClear: return module_->clear();
      case Hook::kReinit: return module_->reinit();
      case Hook::kSync: return module_->sync();
    }
    return Status::fail("unknown method");
  } catch (const std::exception& e) {
    // Copy without allocating: the reason must outlive the exception object.
    std::size_t n = 0;
    for (const char* s = e.what(); *s != '\0' && n + 1 < exception_text_.size(); ++s) exception_text_[n++] = *s;
    exception_text_[n] = '\0';
    return Status::fail(exception_text_.data());
  } catch (...) {
    return Status::fail("an exception that is not a std::exception");
  }
}

Status Task::call(Hook hook) noexcept {
  local_->pull_in_vars();
  const Status s = call_raw(hook);
  // Given up while it ran: the task is ERROR, and its outputs are no longer this thread's to publish.
  if (given_up_meanwhile()) return Status::fail("given up while stuck in a method");
  if (hook != Hook::kKill) local_->push_out_vars(timing_.release_ns);  // a killed module has nothing left to publish
  return s;
}

bool Task::given_up_meanwhile() noexcept {
  if (given_up_ || method_scope_ == nullptr) return given_up_;
  if (method_scope_->returned(method_scope_->method())) given_up_ = true;
  return given_up_;
}

Error Task::given_up_error() const {
  return make_error(Errc::kModuleFault,
                    fmt::format("{}: stuck in a method, and given up; the task is in ERROR", spec_.name));
}

bool Task::recover(Hook hook, Status failure, std::int64_t now_ns) noexcept {
  shared_->events.push(now_ns, hook_name(static_cast<std::uint8_t>(hook)), " failed: ", failure.reason());
  timing_.fault = Fault::kMethodFailed;
  const Status handled = call(Hook::kError);
  timing_.fault = Fault::kNone;
  if (given_up_) return false;  // the watch set ERROR, and the task is no longer ours
  if (handled.is_ok()) {
    shared_->events.push(now_ns, "error() recovered", nullptr);
    return true;
  }
  set_state(TaskState::kError);
  shared_->events.push(now_ns, "ERROR: operator intervention required (clear): ", failure.reason());
  return false;
}

std::int64_t Task::exec_clock_now() const noexcept {
  if (exec_clock_ == ExecClock::kWall) return monotonic_ns();
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::int64_t Task::absolute_deadline(std::int64_t release_ns) const noexcept {
  if (spec_.deadline_ns <= 0) return std::numeric_limits<std::int64_t>::max();
  return release_ns + spec_.deadline_ns;
}

std::int64_t Task::begin_job(std::int64_t release_ns, std::int64_t start_ns) noexcept {
  if (state() != TaskState::kOn) return -1;
  timing_.release_ns = release_ns;
  timing_.start_ns = start_ns;
  job_ = Job{true, false, release_ns, start_ns, exec_clock_now()};
  module_->virtual_ns_ = 0;
  local_->pull_in_vars();
  BusyScope busy(*shared_, BusyIn::kCycle, start_ns);
  // An aperiodic task first takes its event from the resource port, then processes it.
  Hook hook = Hook::kSync;
  Status s = trigger_.any() ? call_raw(Hook::kSync) : Status::ok();
  if (s.is_ok()) {
    hook = Hook::kCycle;
    s = call_raw(Hook::kCycle);
  }
  // Given up while stuck in there (give_up): the task is ERROR, and nothing more of it is ours.
  if (busy.returned(s.is_ok() ? std::nullopt : std::optional(BusyIn::kError))) {
    job_.open = false;
    given_up_ = true;
    return 0;
  }
  if (!s.is_ok()) {
    local_->push_out_vars(release_ns);  // what the failed method wrote is published, as after any method
    job_.failed = true;
    method_scope_ = &busy;  // error() is watched as the cycle was
    (void)recover(hook, s, start_ns);
    method_scope_ = nullptr;
    if (given_up_) {
      job_.open = false;
      return 0;
    }
  }
  return spec_.virtual_exec_ns + module_->virtual_ns_;
}

std::int64_t Task::end_job(std::int64_t end_ns, std::int64_t used_ns) noexcept {
  if (!job_.open) return 0;
  job_.open = false;
  if (!job_.failed && local_) local_->push_out_vars(job_.release_ns);
  const std::int64_t host_ns = exec_clock_now() - job_.exec_start;
  // On the virtual clock the job took its simulated time, which the statistics record as its
  // execution time (the time the schedule was made of); the host's time is kept apart.
  const bool simulated = used_ns >= 0;
  if (!simulated) used_ns = host_ns;
  const bool missed = end_ns > absolute_deadline(job_.release_ns);
  const bool overrun = spec_.wcet_ns.has_value() && used_ns > *spec_.wcet_ns;
  shared_->stats.record_cycle(job_.start_ns - job_.release_ns, used_ns, end_ns - job_.release_ns, missed, overrun);
  if (history_ != nullptr) {
    const CycleRecord record{job_.start_ns - job_.release_ns, used_ns, end_ns - job_.release_ns,
                             (missed ? CycleRecord::kMissed : 0) | (overrun ? CycleRecord::kOverrun : 0) |
                                 (job_.failed ? CycleRecord::kFailed : 0)};
    history_->write(static_cast<std::size_t>(timing_ring_), job_.release_ns, &record);
  }
  if (simulated) shared_->stats.record_host_exec(host_ns);
  ++timing_.cycle;
  if ((missed || overrun) && hard() && state() == TaskState::kOn)
    timing_fault(missed ? Fault::kDeadlineMissed : Fault::kBudgetOverrun, end_ns);
  return used_ns;
}

bool Task::reads_const(std::string_view name) const {
  return std::ranges::any_of(resolved_.bindings,
                             [&](const PortBinding& b) { return b.kind == PortKind::kInConst && b.variable == name; });
}

std::vector<std::string> Task::const_outputs() const {
  std::vector<std::string> out;
  for (const auto& b : resolved_.bindings)
    if (b.kind == PortKind::kOutConst) out.push_back(b.variable);
  return out;
}

bool Task::reinit(std::int64_t now_ns) noexcept {
  if (state() != TaskState::kOn) return false;
  local_->pull_in_consts();
  reinits_.fetch_add(1, std::memory_order_relaxed);  // a counter read on its own
  BusyScope busy(*shared_, BusyIn::kReinit, now_ns);
  method_scope_ = &busy;
  const Status s = call(Hook::kReinit);
  const bool recovered = given_up_ || s.is_ok() || recover(Hook::kReinit, s, now_ns);
  method_scope_ = nullptr;
  if (given_up_ || !recovered) return false;
  return state() == TaskState::kOn;
}

void Task::skip_releases(std::uint64_t n, std::int64_t now_ns) noexcept {
  if (n == 0) return;
  shared_->stats.record_skipped(n);
  if (history_ != nullptr) {
    const CycleRecord record{static_cast<std::int64_t>(n), 0, 0, CycleRecord::kSkipped};
    history_->write(static_cast<std::size_t>(timing_ring_), now_ns, &record);
  }
  if (hard() && state() == TaskState::kOn) timing_fault(Fault::kDeadlineMissed, now_ns);
}

void Task::timing_fault(Fault fault, std::int64_t now_ns) noexcept {
  const char* what = fault == Fault::kDeadlineMissed ? "missed its deadline" : "overran its wcet budget";
  ++timing_faults_;
  timing_.fault = fault;
  const Status handled = call(Hook::kError);
  timing_.fault = Fault::kNone;
  if (handled.is_ok()) {
    // A recovered timing fault can repeat every cycle: tell the operator at 1, 2, 4, 8... so the
    // ring never floods while the count stays visible in the timing table.
    if (std::has_single_bit(timing_faults_)) {
      std::array<char, 24> count{};
      const auto [end, ec] = std::to_chars(count.data(), count.data() + count.size() - 1, timing_faults_);
      *end = '\0';
      (void)ec;  // 24 characters hold any 64-bit count
      shared_->events.push(now_ns, what, "; error() recovered; timing faults so far: ", count.data());
    }
    return;
  }
  set_state(TaskState::kError);
  shared_->events.push(now_ns, "ERROR: operator intervention required (clear): ", what);
}

void Task::set_state(TaskState s) noexcept {
  // Only the thread carrying out this task's methods changes its state, so `before` is current.
  const TaskState before = shared_->state.load(std::memory_order_relaxed);
  // The paper's flag also marks an error in the subsystem, so that critical modules keep the
  // system safe: a task in ERROR holds it, from before its state says ERROR until after it no
  // longer does, so whoever sees the task in ERROR sees the flag up.
  if (s == TaskState::kError && before != TaskState::kError) {
    shared_->ever_in_error.store(true, std::memory_order_relaxed);  // a latch, read on its own
    table_.raise_illegal_configuration();
  }
  // Release: what the method did is visible to whoever sees the state.
  shared_->state.store(s, std::memory_order_release);
  if (before == TaskState::kError && s != TaskState::kError) table_.lower_illegal_configuration();
}

Result<void> Task::apply(Signal signal, std::int64_t now_ns) {
  const TaskState from = state();
  if (!transition(from, signal))
    return make_error(Errc::kState, fmt::format("{}: cannot {} a task that is {}", spec_.name, signal_name(signal),
                                                state_name(from)));
  static constexpr std::array<BusyIn, 5> kMethodOf = {BusyIn::kInit, BusyIn::kOn, BusyIn::kOff, BusyIn::kKill,
                                                      BusyIn::kClear};
  BusyScope busy(*shared_, kMethodOf[static_cast<std::size_t>(signal)], now_ns);
  method_scope_ = &busy;
  Result<void> r = make_error(Errc::kState, "unknown signal");
  switch (signal) {
    case Signal::kSpawn: r = spawn(now_ns); break;
    case Signal::kOn: r = turn_on(now_ns); break;
    case Signal::kOff: r = turn_off(now_ns); break;
    case Signal::kKill: r = kill(now_ns); break;
    case Signal::kClear: r = clear(now_ns); break;
  }
  method_scope_ = nullptr;
  return given_up_ ? Result<void>(given_up_error()) : r;
}

Result<void> Task::spawn(std::int64_t now_ns) {
  auto local = LocalTable::create(table_, resolved_.bindings);
  if (!local) return make_error(Errc::kModuleFault, fmt::format("{}: {}", spec_.name, local.error().message));
  local_ = std::make_unique<LocalTable>(std::move(*local));
  local_->keep_history(history_, ring_of_var_);
  // Out-consts start as the values the module declared (what verification already used); a
  // module may still write them in init.
  for (const auto& port : resolved_.decls.ports()) {
    if (port.kind != PortKind::kOutConst) continue;
    if (auto out = local_->output<double>(port.name))
      for (std::size_t i = 0; i < out->size() && i < port.value.size(); ++i) (*out)[i] = port.value[i];
  }
  module_ = resolved_.module->make();
  timing_ = CycleTiming{now_ns, now_ns, spec_.period_ns.value_or(0), 0, virtual_clock_, Fault::kNone};
  trigger_ = Trigger{};
  job_ = Job{};

  InitContext ctx(spec_.name, spec_.params, *local_, timing_, flags_, trigger_, services_);
  local_->pull_in_consts();
  local_->pull_in_vars();
  Status s = Status::ok();
  std::string reason;
  try {
    s = module_->init(ctx);
    if (s.is_ok() && ctx.failed()) reason = ctx.binding_error();
    if (!s.is_ok()) reason = s.reason();
  } catch (const std::exception& e) {
    reason = fmt::format("exception: {}", e.what());
  } catch (...) {
    reason = "an exception that is not a std::exception";
  }
  // Given up while stuck in init: the module and its table stay as they are, the thread's to leave.
  if (given_up_meanwhile()) return given_up_error();
  if (!reason.empty()) {
    // The paper's rule: an error in init prevents creation and calls kill to free what init took.
    (void)call_raw(Hook::kKill);
    destroy_module();
    shared_->events.push(now_ns, "init failed; task not created: ", reason.c_str());
    return make_error(Errc::kModuleFault, init_failure_message(spec_, ctx.refused_param(), reason));
  }
  // Publishing what init produced lets consumers start from real values; not while another
  // producer of these variables is ON (a task created in the background for a switch): one
  // writer per variable at any time. Its on() publishes them when it joins.
  if (publish_at_spawn_) {
    local_->push_out_consts();
    local_->push_out_vars(now_ns);
  }
  if (!periodic() && !trigger_.any())
    shared_->events.push(now_ns, "aperiodic, and its module declared no trigger in init: it will never cycle", nullptr);
  trigger_var_ = -1;
  if (!trigger_.update_port.empty()) {
    for (const auto& b : resolved_.bindings)
      if (b.port == trigger_.update_port)
        if (auto v = table_.find(b.variable)) trigger_var_ = static_cast<int>(*v);
  }
  set_state(TaskState::kOff);
  return {};
}

Result<void> Task::turn_on(std::int64_t now_ns) {
  // A task joining starts from a fresh local table: inputs read anew, nothing stale kept.
  local_->reset_inputs();
  local_->pull_in_consts();
  timing_.release_ns = now_ns;
  const Status s = call(Hook::kOn);
  if (given_up_) return given_up_error();
  if (s.is_ok()) {
    // Its out-consts are the subsystem's again: another producer of one of them may have
    // published a different value while this task was off (a switch back).
    local_->push_out_consts();
    set_state(TaskState::kOn);
    return {};
  }
  const bool recovered = recover(Hook::kOn, s, now_ns);
  return make_error(Errc::kModuleFault,
                    fmt::format("{}: on failed: {}{}", spec_.name, s.reason(),
                                recovered ? " (error() recovered; task stays OFF)" : "; task is in ERROR"));
}

Result<void> Task::turn_off(std::int64_t now_ns) {
  const Status s = call(Hook::kOff);
  if (given_up_) return given_up_error();
  if (s.is_ok()) {
    set_state(TaskState::kOff);
    return {};
  }
  if (recover(Hook::kOff, s, now_ns)) {
    set_state(TaskState::kOff);
    return {};
  }
  return make_error(Errc::kModuleFault, fmt::format("{}: off failed: {}; task is in ERROR", spec_.name, s.reason()));
}

Result<void> Task::kill(std::int64_t now_ns) {
  std::string problem;
  if (state() == TaskState::kOn) {
    const Status off = call(Hook::kOff);
    if (given_up_) return given_up_error();
    if (!off.is_ok()) problem = fmt::format("off failed: {}; ", off.reason());
  }
  const Status s = call(Hook::kKill);
  if (given_up_) return given_up_error();
  if (!s.is_ok()) problem += fmt::format("kill failed: {}", s.reason());
  // A task is destroyed by kill whatever its methods say: its resources are the module's to free.
  destroy_module();
  set_state(TaskState::kNotCreated);
  if (!problem.empty()) {
    shared_->events.push(now_ns, "killed with a fault: ", problem.c_str());
    return make_error(Errc::kModuleFault, fmt::format("{}: {} (task destroyed)", spec_.name, problem));
  }
  return {};
}

Result<void> Task::clear(std::int64_t now_ns) {
  const Status s = call(Hook::kClear);
  if (given_up_) return given_up_error();
  if (!s.is_ok()) {
    shared_->events.push(now_ns, "clear refused; still in ERROR: ", s.reason());
    return make_error(Errc::kModuleFault,
                      fmt::format("{}: clear failed: {}; task stays in ERROR", spec_.name, s.reason()));
  }
  set_state(TaskState::kOff);
  return {};
}

void Task::lose_process(const char* reason, std::int64_t now_ns) noexcept {
  // The dead process may have died inside a method, or a job: neither its heartbeat nor the job's
  // overrun may outlive it.
  shared_->busy_since_ns.store(TaskShared::kIdle, std::memory_order_release);  // release: as in BusyScope
  set_running_deadline(TaskShared::kNoJob);
  const TaskState before = state();
  if (before == TaskState::kNotCreated) return;
  if (before != TaskState::kError) set_state(TaskState::kError);
  shared_->events.push(now_ns, "ERROR: ", reason, "; operator intervention required (clear)");
}

bool Task::give_up(std::int64_t since_ns, const char* reason, std::int64_t now_ns) noexcept {
  std::int64_t stamp = since_ns;
  // acq_rel: acquire sees what the task's thread did before the method began; release pairs with
  // its exchange in BusyScope::returned, which then sees the ERROR set below.
  if (!shared_->busy_since_ns.compare_exchange_strong(stamp, TaskShared::kGivenUp, std::memory_order_acq_rel,
                                                      std::memory_order_relaxed))
    return false;  // that method has returned
  if (state() != TaskState::kError) set_state(TaskState::kError);
  shared_->events.push(now_ns, "ERROR: ", reason, "");
  return true;
}

bool Task::forget_lost_process() noexcept {
  const TaskState before = state();
  if (before == TaskState::kNotCreated) return false;
  set_state(TaskState::kNotCreated);  // from ERROR: gives the hold back
  return true;
}

void Task::destroy_module() noexcept {
  module_.reset();
  local_.reset();
}

}  // namespace chimera
