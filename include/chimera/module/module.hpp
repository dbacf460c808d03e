#pragma once
// The port-based object (paper 3.3, Figure 7): what a module author writes.
//
//   class Pid final : public chimera::Module {
//    public:
//     static constexpr const char* kName = "pid_joint";
//     static constexpr const char* kSummary = "PID joint position controller";
//     static constexpr const char* kDoc = "tau = Kp e + Ki int(e) + Kd de/dt ...";
//     static void declare(chimera::Declarations& d, const chimera::Params&) {
//       d.in_const("ndof", chimera::Dim::fixed(1), "degrees of freedom");
//       d.in_var("theta_d", chimera::Dim::of("ndof"), "desired joint positions, rad");
//       d.out_var("tau_r", chimera::Dim::of("ndof"), "reference torques, N*m");
//       d.param("kp", 100.0, "N*m/rad", "proportional gain");
//     }
//    protected:
//     chimera::Status init(chimera::InitContext& ctx) override {
//       theta_d_ = ctx.in<double>("theta_d");   // resolved once, by port name
//       tau_r_ = ctx.out<double>("tau_r");
//       kp_ = ctx.params().number("kp");
//       return chimera::Status::ok();
//     }
//     chimera::Status cycle() override { ... touches only theta_d_, tau_r_ ... }
//    private:
//     chimera::In<double> theta_d_; chimera::Out<double> tau_r_; double kp_ = 0;
//   };
//   CHIMERA_REGISTER_MODULE(Pid);
//
// The framework calls the methods (never the module itself), transfers the state variables
// before and after each, times them, and turns a failure or an exception into the lifecycle's
// error path. init, reinit and kill may allocate; on, cycle, off, error, clear and sync run on
// the task's real-time thread and should not.

#include <cstdint>
#include <string>
#include <string_view>

#include "chimera/core/result.hpp"
#include "chimera/module/declarations.hpp"
#include "chimera/module/params.hpp"
#include "chimera/svt/elem_type.hpp"
#include "chimera/svt/port_access.hpp"
#include "chimera/svt/view.hpp"

namespace chimera {

/// Why the framework called error(): a method that failed, or a timing failure it detected.
enum class Fault : std::uint8_t {
  kNone,
  kMethodFailed,    // a method returned a failure or threw
  kDeadlineMissed,  // a cycle ended after its deadline, or a release was skipped past its deadline
  kBudgetOverrun,   // a cycle ran longer than the task's declared wcet
};

/// Timing of the current cycle, kept up to date by the framework; modules read it through the
/// reference InitContext::timing() hands out. Times come from the subsystem's clock (real or
/// virtual), so modules that use them stay deterministic on the virtual clock.
struct CycleTiming {
  std::int64_t release_ns = 0;  // nominal release of the current cycle, since subsystem start
  std::int64_t start_ns = 0;    // when the current cycle started, same clock
  std::int64_t period_ns = 0;   // 0 for an aperiodic task
  std::uint64_t cycle = 0;      // cycles completed before this one
  bool virtual_clock = false;   // the subsystem runs on the simulated clock
  Fault fault = Fault::kNone;   // during error(): what went wrong
};

/// Read-only facts about the running subsystem that any module may look at.
class SubsystemFlags {
 public:
  virtual ~SubsystemFlags() = default;
  /// The paper's illegal-configuration flag (section 3.4). Real-time safe.
  [[nodiscard]] virtual bool illegal_configuration() const noexcept = 0;
};

/// Where a module's requests for a dynamic reconfiguration go: the subsystem interface, which
/// carries one out when the file's `requests:` allow it. Implemented by the framework.
class RequestBoard {
 public:
  virtual ~RequestBoard() = default;
  /// The index of configuration `name`, or -1 if the file has none of that name. Not real-time safe.
  [[nodiscard]] virtual int configuration_index(std::string_view name) const = 0;
  /// Task `task` asks for configuration `configuration`. Real-time safe.
  virtual void post(int task, int configuration) noexcept = 0;
};

/// A switch a module may ask for (paper 3.4: "a signal is sent to the subsystem interface
/// indicating that a dynamic reconfiguration is required"), resolved by name in init.
class SwitchRequest {
 public:
  SwitchRequest() = default;
  SwitchRequest(RequestBoard* board, int task, int configuration)
      : board_(board), task_(task), configuration_(configuration) {}
  /// Asks for the switch; asking again while it is pending or done changes nothing. Real-time safe.
  void ask() const noexcept {
    if (board_ != nullptr) board_->post(task_, configuration_);
  }
  [[nodiscard]] bool bound() const noexcept { return board_ != nullptr; }

 private:
  RequestBoard* board_ = nullptr;
  int task_ = -1;
  int configuration_ = -1;
};

/// What wakes an aperiodic task (paper 3.3: events arrive through its resource port). A periodic
/// task's trigger is its timer and this stays empty.
struct Trigger {
  int fd = -1;              // a cycle each time this descriptor is readable (socket, timerfd, pipe)
  std::string update_port;  // a cycle each time this in-var gets a new value ("" for none)
  [[nodiscard]] bool any() const { return fd >= 0 || !update_port.empty(); }
};

/// The framework's services for one task: where its switch requests go (may be null), and which
/// task it is there.
struct TaskServices {
  RequestBoard* requests = nullptr;
  int task_index = -1;
};

/// What a module receives in init(): its parameters, its typed port views, its timing.
class InitContext {
 public:
  InitContext(std::string_view task_name, const Params& params, PortAccess& ports, const CycleTiming& timing,
              const SubsystemFlags& flags, Trigger& trigger, TaskServices services = {})
      : task_name_(task_name),
        params_(params),
        ports_(ports),
        timing_(timing),
        flags_(flags),
        trigger_(trigger),
        services_(services) {}

  /// A view onto input port `port` (in-var or in-const). A wrong name, kind or element type
  /// returns an unbound view and makes init fail with a message naming the port.
  template <class T>
  In<T> in(std::string_view port) {
    std::string error;
    const PortWindow w = ports_.bind(port, /*input=*/true, kElemTypeOf<T>, error);
    if (w.data == nullptr) {
      note_failure(error);
      return {};
    }
    return In<T>(static_cast<const T*>(w.data), w.count, w.freshness);
  }
  /// A view onto output port `port` (out-var or out-const); same failure rule as in().
  template <class T>
  Out<T> out(std::string_view port) {
    std::string error;
    const PortWindow w = ports_.bind(port, /*input=*/false, kElemTypeOf<T>, error);
    if (w.data == nullptr) {
      note_failure(error);
      return {};
    }
    return Out<T>(static_cast<T*>(w.data), w.count);
  }

  /// Aperiodic tasks: run a cycle (after sync()) each time `fd` is readable. The module owns the
  /// descriptor and closes it in kill(). Level-triggered: sync() should take one event.
  void trigger_on_fd(int fd) { trigger_.fd = fd; }
  /// Aperiodic tasks: run a cycle each time in-var `port` is written anew by its producer.
  void trigger_on_update(std::string_view port) { trigger_.update_port = std::string(port); }

  /// A handle to ask, from cycle(), for a switch to configuration `configuration` of the file.
  /// An unknown name makes init fail with a message naming it. Whether the switch is allowed is
  /// the file's `requests:` to say, when it is asked for.
  SwitchRequest switch_request(std::string_view configuration) {
    const int index = services_.requests != nullptr ? services_.requests->configuration_index(configuration) : -1;
    if (index < 0) {
      note_failure("no configuration named '" + std::string(configuration) + "' to ask a switch to");
      return {};
    }
    return SwitchRequest(services_.requests, services_.task_index, index);
  }

  [[nodiscard]] const Params& params() const { return params_; }
  [[nodiscard]] std::string_view task_name() const { return task_name_; }
  [[nodiscard]] const CycleTiming& timing() const { return timing_; }
  [[nodiscard]] const SubsystemFlags& flags() const { return flags_; }
  /// Period in seconds (0 for aperiodic tasks).
  [[nodiscard]] double period_s() const { return static_cast<double>(timing_.period_ns) * 1e-9; }

  /// Init's refusal of parameter `param`'s value (`reason` as for Status::fail): the framework's
  /// message then points at the line of the subsystem file that gives it, or the task's line.
  Status refuse(std::string_view param, const char* reason) {
    refused_param_ = std::string(param);
    return Status::fail(reason);
  }

  [[nodiscard]] bool failed() const { return !binding_error_.empty(); }
  [[nodiscard]] const std::string& binding_error() const { return binding_error_; }
  /// The parameter named by refuse(), "" if none.
  [[nodiscard]] const std::string& refused_param() const { return refused_param_; }

 private:
  void note_failure(const std::string& message) {
    if (binding_error_.empty()) binding_error_ = message;
  }

  std::string_view task_name_;
  const Params& params_;
  PortAccess& ports_;
  const CycleTiming& timing_;
  const SubsystemFlags& flags_;
  Trigger& trigger_;
  TaskServices services_;
  std::string binding_error_;
  std::string refused_param_;
};

class Task;

/// Base class of every module. Override only the methods you need; the defaults succeed,
/// except error(), whose default reports that the fault was not recovered.
class Module {
 public:
  Module() = default;
  Module(const Module&) = delete;
  Module& operator=(const Module&) = delete;
  virtual ~Module() = default;

 protected:
  /// Create: bind ports, allocate, open resources. An error here calls kill().
  virtual Status init(InitContext& /*ctx*/) { return Status::ok(); }
  /// Activate: bring internal state up to the subsystem's current state.
  virtual Status on() { return Status::ok(); }
  /// One period (or one event of an aperiodic task).
  virtual Status cycle() { return Status::ok(); }
  /// Deactivate; leave the subsystem in a safe state.
  virtual Status off() { return Status::ok(); }
  /// Destroy: free what init took.
  virtual Status kill() { return Status::ok(); }
  /// Called after any other method failed; ok() means the fault was handled and the task goes
  /// on, a failure sends it to ERROR until an operator's clear.
  virtual Status error() { return Status::fail("module has no error handler"); }
  /// The operator says the fault is fixed; ok() only if it really is (the task returns to OFF).
  virtual Status clear() { return Status::ok(); }
  /// An in-const changed (another producer of it joined); the new values are in the views.
  virtual Status reinit() { return Status::ok(); }
  /// Aperiodic tasks: the trigger declared in init fired; take the event from the resource port
  /// (without blocking) before cycle() processes it. A failure skips the cycle (error path).
  virtual Status sync() { return Status::ok(); }

  /// On the virtual clock, makes the current cycle take `ns` more simulated time (what-if
  /// studies, injected overruns); on the real clock time is measured and this does nothing.
  /// Real-time safe.
  void consume_virtual_time(std::int64_t ns) noexcept { virtual_ns_ += ns > 0 ? ns : 0; }

 private:
  friend class Task;             // the framework's non-virtual interface calls the hooks above
  std::int64_t virtual_ns_ = 0;  // charged by the current method; read and reset by the Task
};

}  // namespace chimera
