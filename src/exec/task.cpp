#include "chimera/exec/task.hpp"

#include <array>
#include <exception>

#include <fmt/format.h>

#include "chimera/exec/clock.hpp"

namespace chimera {

namespace {
const char* hook_name(std::uint8_t hook) {
  static constexpr std::array<const char*, 8> kNames = {"on",    "cycle", "off",    "kill",
                                                        "error", "clear", "reinit", "sync"};
  return kNames[hook];
}
}  // namespace

Task::Task(const ResolvedTask& resolved, GlobalTable& table, const SubsystemFlags& flags)
    : spec_(*resolved.spec), resolved_(resolved), table_(table), flags_(flags) {
  timing_.period_ns = spec_.period_ns.value_or(0);
}

Task::~Task() {
  if (state() != TaskState::kNotCreated) (void)apply(Signal::kKill, timing_.release_ns);
}

void Task::set_state(TaskState s) noexcept {
  state_.store(s, std::memory_order_release);  // release: what the method did is visible to whoever sees the state
  if (s == TaskState::kError) ever_in_error_.store(true, std::memory_order_relaxed);  // a latch, read on its own
}

Status Task::call_raw(Hook hook) noexcept {
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
  if (hook != Hook::kKill) local_->push_out_vars();  // a killed module has nothing left to publish
  return s;
}

bool Task::recover(Hook hook, Status failure, std::int64_t now_ns) noexcept {
  events_.push(now_ns, hook_name(static_cast<std::uint8_t>(hook)), " failed: ", failure.reason());
  const Status handled = call(Hook::kError);
  if (handled.is_ok()) {
    events_.push(now_ns, "error() recovered", nullptr);
    return true;
  }
  set_state(TaskState::kError);
  events_.push(now_ns, "ERROR: operator intervention required (clear): ", failure.reason());
  return false;
}

void Task::run_cycle(std::int64_t release_ns, std::int64_t start_ns, std::int64_t deadline_ns,
                     bool clock_is_virtual) noexcept {
  if (state() != TaskState::kOn) return;
  timing_.release_ns = release_ns;
  const std::int64_t exec_start = monotonic_ns();
  const Status s = call(Hook::kCycle);
  const std::int64_t exec_ns = monotonic_ns() - exec_start;
  if (!s.is_ok()) (void)recover(Hook::kCycle, s, start_ns);
  // On the virtual clock a cycle takes no simulated time, so only a late start can miss.
  const std::int64_t end_ns = clock_is_virtual ? start_ns : start_ns + exec_ns;
  const bool missed = end_ns > release_ns + deadline_ns;
  stats_.record_cycle(start_ns - release_ns, exec_ns, missed);
  ++timing_.cycle;
}

Result<void> Task::apply(Signal signal, std::int64_t now_ns) {
  const TaskState from = state();
  if (!transition(from, signal))
    return make_error(Errc::kState, fmt::format("{}: cannot {} a task that is {}", spec_.name, signal_name(signal),
                                                state_name(from)));
  switch (signal) {
    case Signal::kSpawn: return spawn(now_ns);
    case Signal::kOn: return turn_on(now_ns);
    case Signal::kOff: return turn_off(now_ns);
    case Signal::kKill: return kill(now_ns);
    case Signal::kClear: return clear(now_ns);
  }
  return make_error(Errc::kState, "unknown signal");
}

Result<void> Task::spawn(std::int64_t now_ns) {
  auto local = LocalTable::create(table_, resolved_.bindings);
  if (!local) return make_error(Errc::kModuleFault, fmt::format("{}: {}", spec_.name, local.error().message));
  local_ = std::make_unique<LocalTable>(std::move(*local));
  module_ = resolved_.module->make();
  timing_ = CycleTiming{now_ns, spec_.period_ns.value_or(0), 0};

  InitContext ctx(spec_.name, spec_.params, *local_, timing_, flags_);
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
  if (!reason.empty()) {
    // The paper's rule: an error in init prevents creation and calls kill to free what init took.
    (void)call_raw(Hook::kKill);
    destroy_module();
    events_.push(now_ns, "init failed; task not created: ", reason.c_str());
    return make_error(Errc::kModuleFault, fmt::format("{}: init failed: {}", spec_.name, reason));
  }
  local_->push_out_consts();
  local_->push_out_vars();
  set_state(TaskState::kOff);
  return {};
}

Result<void> Task::turn_on(std::int64_t now_ns) {
  // A task joining starts from a fresh local table: inputs read anew, nothing stale kept.
  local_->reset_inputs();
  local_->pull_in_consts();
  timing_.release_ns = now_ns;
  const Status s = call(Hook::kOn);
  if (s.is_ok()) {
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
    if (!off.is_ok()) problem = fmt::format("off failed: {}; ", off.reason());
  }
  const Status s = call(Hook::kKill);
  if (!s.is_ok()) problem += fmt::format("kill failed: {}", s.reason());
  // A task is destroyed by kill whatever its methods say: its resources are the module's to free.
  destroy_module();
  set_state(TaskState::kNotCreated);
  if (!problem.empty()) {
    events_.push(now_ns, "killed with a fault: ", problem.c_str());
    return make_error(Errc::kModuleFault, fmt::format("{}: {} (task destroyed)", spec_.name, problem));
  }
  return {};
}

Result<void> Task::clear(std::int64_t now_ns) {
  const Status s = call(Hook::kClear);
  if (!s.is_ok()) {
    events_.push(now_ns, "clear refused; still in ERROR: ", s.reason());
    return make_error(Errc::kModuleFault,
                      fmt::format("{}: clear failed: {}; task stays in ERROR", spec_.name, s.reason()));
  }
  set_state(TaskState::kOff);
  return {};
}

void Task::destroy_module() noexcept {
  module_.reset();
  local_.reset();
}

}  // namespace chimera
