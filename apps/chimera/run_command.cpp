// chimera run FILE [--config NAME] [--for DURATION] [--clock real|virtual] [--stats-json FILE]
// [--rt-check] [--listen [ADDR:]PORT [--token-file FILE]], and chimera serve (no file):
// starts the subsystem, takes commands from a shell or a script on stdin (and from the network
// API, network.hpp), stops it cleanly.

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/control.hpp"
#include "chimera/control/stats_json.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/control/timing_table.hpp"
#include "chimera/module/registry.hpp"
#include "commands.hpp"
#include "dds_bridge.hpp"
#include "exit_codes.hpp"
#include "line_reader.hpp"
#include "load_file.hpp"
#include "network.hpp"
#include "ordinary_cpus.hpp"
#include "rt_check_allocator.hpp"
#include "stop_request.hpp"

namespace chimera::cli {

namespace {

// How often the loop looks at signals, events and --for while it waits, in both clocks' time.
constexpr std::int64_t kStepNs = 50'000'000;
constexpr int kPollMs = 50;
constexpr std::string_view kPrompt = "chimera> ";

// Replies to commands (and the prompt, and the timing table) go to stdout; what the running
// subsystem says of its own accord (events: a task in ERROR, a switch, a job overdue) and every
// diagnostic go to stderr, so that a script reading the replies gets only replies.
void out(std::string_view text) {
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);  // replies must reach a script reading the pipe as they happen
}

void err(std::string_view text) {
  std::fflush(stdout);  // on a terminal both streams share a screen: keep them in order
  std::fwrite(text.data(), 1, text.size(), stderr);
  std::fflush(stderr);
}

// Refuses a --stats-json path that cannot be written before anything starts, rather than
// losing a whole run's figures at the end.
Result<void> check_writable(const std::string& path) {
  const bool existed = std::filesystem::exists(path);
  {
    std::ofstream probe(path, std::ios::app);
    if (!probe) return make_error(Errc::kInvalidInput, fmt::format("--stats-json: cannot write '{}'", path));
  }
  std::error_code ignored;
  if (!existed) std::filesystem::remove(path, ignored);
  return {};
}

/// The loop between start and stop: commands in, replies and events out, time kept.
class Session {
 public:
  Session(Subsystem& subsystem, net::ControlGate& control, DdsBridge* remote, const RunArgs& args, bool interactive)
      : subsystem_(subsystem), control_(control), remote_(remote), args_(args), interactive_(interactive) {}

  void run() {
    LineReader reader(STDIN_FILENO);
    bool input_open = true;
    bool prompt_shown = false;
    std::string line;
    while (!should_end()) {
      print_events(prompt_shown);
      if (!input_open) {
        run_on();
        continue;
      }
      if (interactive_ && !prompt_shown) {
        out(kPrompt);
        prompt_shown = true;
      }
      switch (reader.next(line, kPollMs)) {
        case LineReader::Status::kTimeout: break;
        case LineReader::Status::kEnd:
          input_open = false;
          if (prompt_shown) out("\n");
          prompt_shown = false;
          // On a terminal Ctrl-D might be taken for quit; say what happens instead.
          if (interactive_) out(end_of_input_text());
          // Simulated time without --for has no end of its own: running on would spin a core
          // forever. The run lasts as long as its input.
          if (stops_at_end_of_input()) return;
          break;
        case LineReader::Status::kLine: {
          prompt_shown = false;
          const Reply reply = control_.execute_line(line);
          out(reply.text);
          if (reply.quit) return;
          if (reply.wait_ns > 0) advance(reply.wait_ns);
          break;
        }
      }
    }
    if (prompt_shown) out("\n");
  }

 private:
  [[nodiscard]] bool time_up() const { return args_.for_ns && subsystem_.now_ns() >= *args_.for_ns; }
  [[nodiscard]] bool stops_at_end_of_input() const {
    return !args_.for_ns && subsystem_.clock() == ClockKind::kVirtual;
  }
  [[nodiscard]] std::string end_of_input_text() const {
    if (args_.for_ns) return "end of input: running on until --for has passed (Ctrl-C stops now)\n";
    if (stops_at_end_of_input())
      return "end of input: stopping (on the virtual clock without --for a run lasts as long as its input)\n";
    return "end of input: running on until Ctrl-C\n";
  }
  [[nodiscard]] bool should_end() const { return stop_requested() || time_up(); }

  void print_events(bool& prompt_shown) {
    std::string events = control_.drain_events();
    // The bridge's news among the subsystem's own: an import stale or back, a remote refused.
    // When the table was made anew it follows the subsystem's file as it is now, read under the
    // gate, so that no command changes the file meanwhile.
    if (remote_ != nullptr) {
      if (remote_->table_made_anew())
        for (const auto& line : control_.exclusive([&](Control&, Subsystem&) { return remote_->follow(); }))
          events += "dds: " + line + "\n";
      for (const auto& line : remote_->news()) events += "dds: " + line + "\n";
    }
    if (events.empty()) return;
    // Keep the operator's prompt usable: events go on their own lines, then the prompt again.
    if (prompt_shown) out("\n");
    err(events);
    prompt_shown = false;
  }

  // Lets the subsystem run for `ns` (capped by --for) in small steps, so that a signal or the
  // end of --for is noticed within a step on either clock.
  void advance(std::int64_t ns) {
    const std::int64_t until = subsystem_.now_ns() + ns;
    bool prompt_shown = false;
    while (!should_end()) {
      std::int64_t left = until - subsystem_.now_ns();
      if (args_.for_ns) left = std::min(left, *args_.for_ns - subsystem_.now_ns());
      if (left <= 0) break;
      control_.run_for(std::min(left, kStepNs));
      print_events(prompt_shown);
    }
  }

  // End of input: run on until --for has passed, or without --for (real clock) until a signal.
  void run_on() {
    if (args_.for_ns)
      advance(*args_.for_ns - subsystem_.now_ns());
    else
      advance(kStepNs);
  }

  Subsystem& subsystem_;
  net::ControlGate& control_;  // shared with the network API
  DdsBridge* remote_;          // the bridge to other subsystems, or none
  const RunArgs& args_;
  bool interactive_;
};

// The flight recorder's dumps: --dump-dir, else chimera-dumps below $CHIMERA_LOG_DIR (where the
// data loggers write) or the working directory.
std::string dump_directory(const RunArgs& args) {
  if (args.dump_dir) return *args.dump_dir;
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read before any thread of the run starts
  const char* logs = std::getenv("CHIMERA_LOG_DIR");
  return logs != nullptr && *logs != '\0' ? std::string(logs) + "/chimera-dumps" : std::string("chimera-dumps");
}

}  // namespace

int run_command(const RunArgs& args) {
  // First of all: a signal that arrives while the file loads or the tasks start must still end
  // in a clean stop (right after start), never in the default action's abrupt exit.
  install_stop_handlers();
  const Registry& registry = Registry::global();
  auto spec = args.file.empty() ? std::optional(empty_subsystem()) : load_file(args.file, args.config);
  if (!spec) return kExitInvalid;
  auto network_plan = plan_network(args);
  if (!network_plan) return kExitInvalid;
  if (args.stats_json) {
    if (auto writable = check_writable(*args.stats_json); !writable) {
      fmt::print(stderr, "{}\n", writable.error().message);
      return kExitInvalid;
    }
  }

  RunOptions options;
  options.clock = args.clock;
  options.configuration = args.config;
  options.rt_check = args.rt_check;
  options.record_seconds = static_cast<double>(args.record_ns) / 1e9;
  options.error_dump_dir = dump_directory(args);
  if (args.rt_check && !kRtCheckAllocator)
    fmt::print(stderr, "--rt-check: this build's allocator belongs to a sanitizer; nothing will be counted\n");
  auto created = Subsystem::create(*spec, registry, options);
  if (!created) {
    fmt::print(stderr, "{}\n", created.error().message);
    return kExitInvalid;
  }
  Subsystem& subsystem = **created;

  if (auto started = subsystem.start(); !started) {
    fmt::print(stderr, "{}\n", started.error().message);
    subsystem.stop();  // start() already undid its work; this also removes the shared memory
    return kExitInvalid;
  }

  // The ordinary threads, these and the ones started below, off the real-time tasks' CPUs where
  // there is a CPU without any (ordinary_cpus.hpp says why).
  if (args.clock == ClockKind::kReal) {
    std::vector<int> realtime_cpus;
    for (const auto& task : subsystem.snapshot()) realtime_cpus.push_back(task.cpu);
    (void)keep_ordinary_threads_on(ordinary_cpus(realtime_cpus));
  }

  // The resource ports to other subsystems: on their own ordinary threads, attached to the table;
  // idle until a file with exports or imports runs (this one, or one opened later).
  std::unique_ptr<DdsBridge> remote;
  {
    auto bridge = DdsBridge::start(subsystem, options.shm_suffix);
    if (!bridge) {
      fmt::print(stderr, "{}: dds: {}\n", spec->file, bridge.error().message);
      subsystem.stop();
      return kExitInvalid;
    }
    remote = std::move(*bridge);
  }
  // `status` shows the imports beside the tasks (the shell's and the network API's).
  subsystem.report_remote_imports([bridge = remote.get()] { return bridge->imports(); });

  const bool interactive = ::isatty(STDIN_FILENO) == 1;
  if (interactive)
    out(fmt::format("subsystem '{}' running configuration '{}' on the {} clock; type help for commands\n", spec->name,
                    args.config.value_or(spec->start), args.clock == ClockKind::kVirtual ? "virtual" : "real"));

  net::ControlGate gate(subsystem);
  std::unique_ptr<Network> network;
  if (*network_plan) {
    auto started = Network::start(std::move(**network_plan), gate, spec->name);
    if (!started) {
      subsystem.stop();
      return kExitInvalid;
    }
    network = std::move(*started);
  }
  Session session(subsystem, gate, remote.get(), args, interactive);
  session.run();
  network.reset();                      // the network API ends before the subsystem stops
  subsystem.report_remote_imports({});  // no command runs any more: the bridge can go
  if (remote) {
    for (const auto& line : remote->stop()) err("dds: " + line + "\n");  // it writes no import after this
    remote.reset();                                                      // before the tasks stop
  }

  std::optional<std::string> exit_dump_failure;
  if (args.dump_at_exit) {
    if (auto written = subsystem.dump(fmt::format("{}/{}-exit", options.error_dump_dir, spec->name), "the run's end");
        written)
      err(fmt::format("flight recorder: the last {:.3g} s written to {}/\n", subsystem.recorded_seconds(), *written));
    else
      exit_dump_failure = written.error().message;
  }

  // Each task's state as it stood while the tasks ran (stopping turns every task NOT-CREATED),
  // with its figures as they stand once stopped: the cycles run between the two count too, as a
  // logger's rows of them do (the hour's soak found one row more than the figures' cycles).
  auto tasks = subsystem.snapshot();
  const std::uint64_t switches = subsystem.switches().size();
  subsystem.stop();
  for (const TaskSnapshot& stopped : subsystem.snapshot())
    for (TaskSnapshot& t : tasks)
      if (t.name == stopped.name) t.stats = stopped.stats;
  Control control(subsystem);
  err(control.drain_events());
  out(timing_table(tasks, args.rt_check));

  // Exit 1 says why in the run's last line: the hard tasks that failed, the modules that could
  // not release their resources cleanly (a data logger's lost rows), figures that were not written.
  std::vector<std::string> faults = subsystem.faults();
  if (exit_dump_failure) {
    err(*exit_dump_failure + "\n");
    faults.push_back(*exit_dump_failure);
  }
  if (args.stats_json) {
    if (auto written = write_stats_json(*args.stats_json, tasks, args.clock, switches, args.rt_check); !written) {
      err(written.error().message + "\n");
      faults.push_back(written.error().message);
    }
  }
  const int code = faults.empty() ? kExitOk : kExitFailed;
  if (!faults.empty()) err(fmt::format("chimera: exit {}: {}\n", code, fmt::join(faults, "; ")));
  spdlog::debug("run ended with exit code {}", code);
  return code;
}

}  // namespace chimera::cli
