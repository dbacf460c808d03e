// Recovery from a stall on the real clock: Figure 4's five-task chain at 1 ms
// (examples/fig4_filtered_chain.yaml: traj -> filter -> pid -> limit -> robot, and the monitor)
// runs with real-time priorities; in the middle of the run a SCHED_FIFO hog, one thread pinned
// to each CPU at a priority above every task's, takes both CPUs for 40 ms, as a VM stall would.
// Then each task must be back on time within a bounded number of periods (docs/scheduling.md,
// "After a stall"). Two placements: the chain on one CPU, and split across both (0/1/0/1/0),
// which automatic placement still makes when a chain does not fit on one CPU.
//
//   stall_bench [--quick] [--out FILE] [--runs N]
//
// Per task and placement: the misses from the stall's start until it is back on time, the periods
// after the stall's end until its last miss before 10 ms without one (0: on time at the first
// release after it; "never" is the whole window), later misses apart (this machine's own
// stalls), order timeouts, its state.
// Keys: stall_recovery_periods_max (worst task, run and placement), stall_tasks_in_error.

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "common/bench_util.hpp"
#include "common/real_subsystem.hpp"

namespace chimera::bench {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kStallNs = 40 * kMs;
constexpr int kHogPriority = 95;  // above every task (80 at most), the commit (85) and the dispatchers

struct Hog {
  int cpu = 0;
  std::int64_t from_ns = 0;
  std::int64_t to_ns = 0;
  bool fifo = false;  // it got SCHED_FIFO at kHogPriority
  pthread_t thread{};
  std::int64_t began_ns = 0;  // when it really took the CPU, and let go
  std::int64_t ended_ns = 0;
};

void sleep_until(std::int64_t t) {
  const timespec ts{static_cast<time_t>(t / 1'000'000'000), static_cast<long>(t % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void* hog_main(void* arg) {
  auto& h = *static_cast<Hog*>(arg);
  sleep_until(h.from_ns);
  h.began_ns = monotonic_ns();
  std::int64_t now = h.began_ns;
  while (now < h.to_ns) now = monotonic_ns();  // busy: the CPU is taken
  h.ended_ns = now;
  return nullptr;
}

bool start_hog(Hog& h) {
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<unsigned>(h.cpu), &set);
  pthread_attr_setaffinity_np(&attr, sizeof(set), &set);
  pthread_attr_setstacksize(&attr, std::size_t{256} << 10);  // mlockall locks it: keep it small
  sched_param sp{};
  sp.sched_priority = kHogPriority;
  pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
  pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
  pthread_attr_setschedparam(&attr, &sp);
  const int rc = pthread_create(&h.thread, &attr, hog_main, &h);
  pthread_attr_destroy(&attr);
  h.fifo = rc == 0;
  return h.fifo;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The example with `cpu: N` added to each task named in `cpus`.
std::string placed(std::string yaml, const std::map<std::string, int>& cpus) {
  for (const auto& [task, cpu] : cpus) {
    const std::string line = "  - name: " + task + "\n";
    const auto at = yaml.find(line);
    if (at != std::string::npos) yaml.insert(at + line.size(), fmt::format("    cpu: {}\n", cpu));
  }
  return yaml;
}

struct TaskOutcome {
  std::uint64_t missed = 0;        // from the stall's start until it was back on time
  std::uint64_t missed_later = 0;  // after that (the machine's own stalls)
  std::uint64_t skipped = 0;
  std::uint64_t order_timeouts = 0;
  std::uint64_t cycles = 0;
  std::int64_t last_miss_ns = -1;  // when its miss count last grew (polled every ms), -1: never
  std::int64_t recovery_periods = 0;
  std::string state;
};

struct RunOutcome {
  std::string error;
  std::map<std::string, TaskOutcome> tasks;
  std::int64_t stall_ns = 0;           // how long the hogs held both CPUs together
  std::int64_t hog_began_late_ns = 0;  // the later hog's start after the planned one
};

RunOutcome run_once(const std::string& yaml, std::int64_t settle_ns, std::int64_t after_ns) {
  RunOutcome out;
  auto sub = real_subsystem(yaml, "fig4_filtered_chain.yaml");
  if (!sub) {
    out.error = sub.error().message;
    return out;
  }
  if (auto r = (*sub)->start(); !r) {
    out.error = r.error().message;
    return out;
  }
  (*sub)->run_for(settle_ns);
  std::map<std::string, TaskSnapshot> before;
  for (auto& t : (*sub)->snapshot()) before[t.name] = t;

  // Far enough ahead that both hogs exist and sleep before it (a thread's start takes a while
  // under mlockall on a loaded machine).
  const std::int64_t from = monotonic_ns() + 100 * kMs;
  std::vector<Hog> hogs(2);
  for (int c = 0; c < 2; ++c) hogs[static_cast<std::size_t>(c)] = Hog{c, from, from + kStallNs};
  for (auto& h : hogs)
    if (!start_hog(h)) {
      out.error = "cannot start a SCHED_FIFO hog thread (SCHED_FIFO not permitted?): no stall to measure";
      for (auto& g : hogs)
        if (g.fifo) pthread_join(g.thread, nullptr);
      (*sub)->stop();
      return out;
    }
  // Poll the miss counts every millisecond from the stall's end on, at a real-time priority below
  // every task's (so that the machine's other programs do not delay the polls). A task is back
  // on time at its last miss before kQuietNs (10 periods) without one; misses after that are the machine's.
  constexpr std::int64_t kQuietNs = 10 * kMs;
  sched_param low{};
  low.sched_priority = 1;
  int old_policy = SCHED_OTHER;
  sched_param old_param{};
  pthread_getschedparam(pthread_self(), &old_policy, &old_param);
  const bool poll_rt = pthread_setschedparam(pthread_self(), SCHED_FIFO, &low) == 0;
  std::map<std::string, std::uint64_t> missed_seen;
  std::map<std::string, bool> recovered;
  for (const auto& [name, t] : before) missed_seen[name] = t.stats.missed;
  const std::int64_t stall_end = from + kStallNs;
  const std::int64_t end = stall_end + after_ns;
  for (std::int64_t t = stall_end; t < end; t += kMs) {
    sleep_until(t);
    const std::int64_t now = monotonic_ns();
    for (const auto& s : (*sub)->snapshot()) {
      TaskOutcome& o = out.tasks[s.name];
      if (s.stats.missed != missed_seen[s.name]) {
        if (recovered[s.name])
          o.missed_later += s.stats.missed - missed_seen[s.name];
        else
          o.last_miss_ns = now;
      }
      missed_seen[s.name] = s.stats.missed;
      if (!recovered[s.name] && now - std::max(o.last_miss_ns, stall_end) >= kQuietNs) recovered[s.name] = true;
    }
  }
  if (poll_rt) pthread_setschedparam(pthread_self(), old_policy, &old_param);
  for (auto& h : hogs) pthread_join(h.thread, nullptr);
  out.stall_ns = std::min(hogs[0].ended_ns, hogs[1].ended_ns) - std::max(hogs[0].began_ns, hogs[1].began_ns);
  out.hog_began_late_ns = std::max(hogs[0].began_ns, hogs[1].began_ns) - from;
  for (const auto& s : (*sub)->snapshot()) {
    const TaskSnapshot& b = before[s.name];
    TaskOutcome& o = out.tasks[s.name];
    o.missed = s.stats.missed - b.stats.missed - o.missed_later;
    o.skipped = s.stats.skipped - b.stats.skipped;
    o.order_timeouts = s.stats.order_timeouts - b.stats.order_timeouts;
    o.cycles = s.stats.cycles - b.stats.cycles;
    o.state = std::string(state_name(s.state));
    // From when the hogs really let go (they start within microseconds of `from` here).
    const std::int64_t let_go = std::max(hogs[0].ended_ns, hogs[1].ended_ns);
    if (o.last_miss_ns > let_go && s.period_ns > 0)
      o.recovery_periods = (o.last_miss_ns - let_go + s.period_ns - 1) / s.period_ns;
    if (!recovered[s.name]) o.recovery_periods = after_ns / std::max<std::int64_t>(1, s.period_ns);  // never
  }
  (*sub)->stop();
  return out;
}

}  // namespace
}  // namespace chimera::bench

int main(int argc, char** argv) {
  using namespace chimera;
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  int runs = args.quick ? 1 : 3;
  for (std::size_t i = 0; i + 1 < args.rest.size(); ++i)
    if (args.rest[i] == "--runs") runs = std::stoi(args.rest[i + 1]);
  const std::string example = read_text(std::string(CHIMERA_EXAMPLES_DIR) + "/fig4_filtered_chain.yaml");
  if (example.empty()) {
    std::fprintf(stderr, "stall_bench: cannot read %s/fig4_filtered_chain.yaml\n", CHIMERA_EXAMPLES_DIR);
    return 1;
  }
  const std::map<std::string, std::map<std::string, int>> placements = {
      {"one_cpu", {{"traj", 0}, {"filter", 0}, {"pid", 0}, {"limit", 0}, {"robot", 0}, {"monitor", 1}}},
      {"split", {{"traj", 0}, {"filter", 1}, {"pid", 0}, {"limit", 1}, {"robot", 0}, {"monitor", 1}}},
  };
  const std::int64_t settle = (args.quick ? 1000 : 2000) * kMs;
  const std::int64_t after = (args.quick ? 1000 : 2000) * kMs;

  Fragment out;
  auto& d = out.details();
  d["stall_ms"] = kStallNs / kMs;
  d["hog"] = fmt::format("one SCHED_FIFO {} thread pinned to each CPU, busy for {} ms", kHogPriority, kStallNs / kMs);
  d["runs_per_placement"] = runs;
  std::int64_t worst = 0;
  int in_error = 0;
  for (const auto& [placement, cpus] : placements) {
    nlohmann::json runs_json = nlohmann::json::array();
    for (int r = 0; r < runs; ++r) {
      const RunOutcome o = run_once(placed(example, cpus), settle, after);
      if (!o.error.empty()) {
        std::fprintf(stderr, "stall_bench: %s: %s\n", placement.c_str(), o.error.c_str());
        d["error"] = placement + ": " + o.error;
        (void)out.write(args);
        return 1;
      }
      nlohmann::json tasks;
      for (const auto& [name, t] : o.tasks) {
        tasks[name] = {{"cpu", cpus.at(name)},
                       {"missed", t.missed},
                       {"missed_later", t.missed_later},
                       {"skipped", t.skipped},
                       {"order_timeouts", t.order_timeouts},
                       {"cycles", t.cycles},
                       {"recovery_periods", t.recovery_periods},
                       {"state", t.state}};
        worst = std::max(worst, t.recovery_periods);
        in_error += t.state == "ERROR" ? 1 : 0;
      }
      runs_json.push_back({{"stall_ms", static_cast<double>(o.stall_ns) / 1e6},
                           {"hog_began_late_us", static_cast<double>(o.hog_began_late_ns) / 1e3},
                           {"tasks", tasks}});
    }
    d["placements"][placement] = runs_json;
  }
  out.result("stall_recovery_periods_max", static_cast<double>(worst));
  out.result("stall_tasks_in_error", in_error);
  return out.write(args);
}
