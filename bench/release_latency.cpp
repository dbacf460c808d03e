// Periodic release latency of a 1 kHz Chimera task against cyclictest (rt-tests), run at the
// same time for the same length, at the same SCHED_FIFO priority and interval, on the same CPU:
// cyclictest's wake-ups are aligned half a period after Chimera's (--secaligned), so the two
// never compete, yet both see the same moments of this shared machine's noise on the same CPU.
// The first half runs on the last CPU, the second on CPU 0. Both are reduced the same way: 1 us
// bins as cyclictest keeps them, percentiles interpolated within a bin.
//
//   release_latency [--quick] [--out FILE] [--samples-dir DIR] [--seconds S] [--cyclictest PATH]
//
// Keys: release_latency_p50_ratio, release_latency_p99_ratio, release_latency_ns_p50/_p99
// (Chimera), cyclictest_latency_ns_p50/_p99.

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "common/bench_util.hpp"
#include "common/real_subsystem.hpp"
#include "support/bench_modules.hpp"

extern char** environ;  // NOLINT: POSIX

namespace chimera::bench {
namespace {

constexpr int kHistogramMaxUs = 10'000;  // cyclictest -h: bins of 1 us up to 10 ms
constexpr int kPriority = 80;            // what Chimera gives its highest-rate tasks
constexpr std::int64_t kPeriodNs = 1'000'000;
constexpr std::int64_t kSecondNs = 1'000'000'000;

/// Latencies in 1 us bins (index = floor(us)), plus the count above the last bin.
struct UsHistogram {
  std::vector<std::uint64_t> bins = std::vector<std::uint64_t>(kHistogramMaxUs, 0);
  std::uint64_t overflow = 0;

  void add_ns(std::int64_t ns) {
    const std::int64_t us = std::max<std::int64_t>(0, ns / 1000);
    if (us >= kHistogramMaxUs) {
      ++overflow;
    } else {
      ++bins[static_cast<std::size_t>(us)];
    }
  }
  [[nodiscard]] std::uint64_t total() const {
    std::uint64_t n = overflow;
    for (const auto b : bins) n += b;
    return n;
  }
  /// Percentile in ns, interpolated linearly inside the bin that holds the rank.
  [[nodiscard]] double percentile_ns(double fraction) const {
    const double rank = fraction * static_cast<double>(total());
    double below = 0;
    for (std::size_t us = 0; us < bins.size(); ++us) {
      const auto n = static_cast<double>(bins[us]);
      if (n > 0 && below + n >= rank) return (static_cast<double>(us) + (rank - below) / n) * 1000.0;
      below += n;
    }
    return static_cast<double>(kHistogramMaxUs) * 1000.0;  // in the overflow
  }
  [[nodiscard]] std::vector<std::uint32_t> as_samples() const {  // lower bin edges, for the plots
    std::vector<std::uint32_t> v;
    for (std::size_t us = 0; us < bins.size(); ++us) v.insert(v.end(), bins[us], static_cast<std::uint32_t>(us * 1000));
    return v;
  }
};

/// cyclictest -h --json: {"thread": {"0": {"histogram": {"us": count}, "cycles": n}}}.
bool read_cyclictest(const std::string& path, UsHistogram& into, std::uint64_t& cycles) {
  std::ifstream f(path);
  if (!f) return false;
  nlohmann::json j;
  try {
    f >> j;
    const auto& t = j.at("thread").at("0");
    std::uint64_t in_bins = 0;
    for (const auto& [us, count] : t.at("histogram").items()) {
      const auto b = static_cast<std::size_t>(std::stoul(us));
      const auto n = count.get<std::uint64_t>();
      if (b < into.bins.size()) into.bins[b] += n;
      in_bins += n;
    }
    const auto c = t.at("cycles").get<std::uint64_t>();
    cycles += c;
    into.overflow += c > in_bins ? c - in_bins : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), e.what());
    return false;
  }
  return true;
}

/// cyclictest on `cpu` for `seconds`, its wake-ups at whole seconds + offset_us + k ms.
pid_t spawn_cyclictest(const std::string& exe, int cpu, int seconds, std::int64_t offset_us, const std::string& json) {
  std::vector<std::string> args = {exe,
                                   "-t1",
                                   fmt::format("-p{}", kPriority),
                                   "--policy=fifo",
                                   "-i1000",
                                   "-m",
                                   "-q",
                                   fmt::format("-a{}", cpu),
                                   fmt::format("-D{}", seconds),
                                   fmt::format("--secaligned={}", offset_us),
                                   fmt::format("-h{}", kHistogramMaxUs),
                                   "--histfile=/dev/null",
                                   "--json=" + json};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

/// The subsystem epoch on CLOCK_MONOTONIC: now - now_ns(), taken where the two reads are closest.
std::int64_t epoch_of(const Subsystem& s) {
  std::int64_t best = std::numeric_limits<std::int64_t>::min();
  for (int i = 0; i < 100; ++i) best = std::max(best, monotonic_ns() - s.now_ns());
  return best;
}

struct Half {
  bool ok = false;
  std::string error;
  TaskSnapshot framework;  // the task's own figures, for comparison
};

Half run_half(int cpu, int seconds, const std::string& cyclictest, const std::string& json, UsHistogram& chimera_hist,
              std::vector<std::uint32_t>& chimera_ns, std::int64_t& cyclictest_first_ns) {
  Half h;
  const std::string yaml = fmt::format(
      "subsystem: bench_release_{}\n"
      "tasks:\n"
      "  - name: probe\n"
      "    module: bench_stamp\n"
      "    period: 1ms\n"
      "    cpu: {}\n"
      // Soft: a hard probe went to ERROR at its first miss (a VM stall) and stamped nothing more;
      // late: run, so that a late release is measured, not skipped.
      "    criticality: soft\n"
      "    late: run\n"
      "configurations:\n"
      "  run: [probe]\n",
      ::getpid(), cpu);
  stamp_log().reserve(static_cast<std::size_t>(seconds) * 1000 + 4000);

  // Chimera first, so that its start (threads, mlockall) falls outside cyclictest's run.
  auto sub = real_subsystem(yaml, "release_latency.yaml");
  if (!sub) {
    h.error = sub.error().message;
    return h;
  }
  if (auto started = (*sub)->start(); !started) {
    h.error = started.error().message;
    return h;
  }
  const std::int64_t epoch = epoch_of(**sub);
  (*sub)->run_for(300'000'000);
  // cyclictest starts its grid at the next whole second (+2 after .9): spawn it early in a
  // second so that it is the next one, and put its wake-ups half a period after Chimera's.
  while (monotonic_ns() % kSecondNs > kSecondNs / 2) (*sub)->run_for(50'000'000);
  const std::int64_t ct_start = monotonic_ns();
  const std::int64_t phase_ns = ((epoch % kPeriodNs) + kPeriodNs) % kPeriodNs;
  const std::int64_t offset_us = ((phase_ns + kPeriodNs / 2) % kPeriodNs) / 1000;
  const pid_t ct = spawn_cyclictest(cyclictest, cpu, seconds, offset_us, json);
  if (ct < 0) {
    h.error = "could not start " + cyclictest;
    return h;
  }
  const std::int64_t grid = (ct_start / kSecondNs + 1) * kSecondNs + offset_us * 1000;  // its k = 0
  cyclictest_first_ns = grid;
  (*sub)->run_for(grid - monotonic_ns() + static_cast<std::int64_t>(seconds) * kSecondNs + 300'000'000);
  (*sub)->stop();
  h.framework = (*sub)->snapshot().front();
  int status = 0;
  ::waitpid(ct, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    h.error = "cyclictest failed (is SCHED_FIFO permitted?)";
    return h;
  }
  // Chimera's releases inside cyclictest's run: from its first wake-up to its last.
  const std::int64_t from = grid;
  const std::int64_t to = grid + static_cast<std::int64_t>(seconds) * kSecondNs;
  const StampLog& log = stamp_log();
  const std::size_t n = log.count.load(std::memory_order_relaxed);  // relaxed: the task's thread has been joined
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t release = epoch + log.release_ns[i];
    if (release < from || release >= to) continue;
    const std::int64_t ns = log.start_ns[i] - release;
    chimera_hist.add_ns(ns);
    chimera_ns.push_back(static_cast<std::uint32_t>(std::clamp<std::int64_t>(ns, 0, 4'000'000'000)));
  }
  h.ok = chimera_hist.total() > 0;
  if (!h.ok)
    h.error = fmt::format(
        "no release of the Chimera task on CPU {} fell inside cyclictest's run ({} cycles stamped in all, {} "
        "deadlines missed, state {}{})",
        cpu, n, h.framework.stats.missed, state_name(h.framework.state),
        h.framework.last_error.empty() ? "" : ", last error: " + h.framework.last_error);
  return h;
}

/// The method's own error: two cyclictests on the same CPU, half a period apart, exactly as
/// Chimera and cyclictest are run, one pair on each CPU at the same time. Their ratio would be
/// 1.00 on a quiet machine; how far it is from that says how much of a Chimera ratio is noise.
bool run_control(int seconds, int last_cpu, const std::string& cyclictest, const std::string& dir, UsHistogram& first,
                 UsHistogram& second) {
  while (monotonic_ns() % kSecondNs > kSecondNs / 2) ::usleep(50'000);
  std::vector<std::pair<pid_t, std::string>> runs;
  for (const int cpu : {0, last_cpu}) {
    for (const std::int64_t offset_us : {std::int64_t{0}, kPeriodNs / 2000}) {
      const std::string json = fmt::format("{}/cyclictest_control_{}_{}.json", dir, cpu, offset_us);
      runs.emplace_back(spawn_cyclictest(cyclictest, cpu, seconds, offset_us, json), json);
      if (cpu == last_cpu && last_cpu == 0) break;  // one CPU: one pair
    }
    if (last_cpu == 0) break;
  }
  bool ok = true;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    int status = 0;
    if (runs[i].first < 0 || ::waitpid(runs[i].first, &status, 0) < 0 || !WIFEXITED(status) ||
        WEXITSTATUS(status) != 0) {
      ok = false;
      continue;
    }
    std::uint64_t cycles = 0;
    ok = read_cyclictest(runs[i].second, i % 2 == 0 ? first : second, cycles) && ok;
  }
  return ok;
}

nlohmann::json describe(const UsHistogram& h) {
  return {{"count", h.total()},           {"p50", h.percentile_ns(0.50)},   {"p90", h.percentile_ns(0.90)},
          {"p99", h.percentile_ns(0.99)}, {"p999", h.percentile_ns(0.999)}, {"over_10ms", h.overflow}};
}

}  // namespace
}  // namespace chimera::bench

int main(int argc, char** argv) {
  using namespace chimera;
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  int seconds = args.quick ? 4 : 25;  // per half
  std::string cyclictest = "cyclictest";
  for (std::size_t i = 0; i + 1 < args.rest.size(); ++i) {
    if (args.rest[i] == "--seconds") seconds = std::max(1, std::stoi(args.rest[i + 1]) / 2);
    if (args.rest[i] == "--cyclictest") cyclictest = args.rest[i + 1];
  }
  const int last_cpu = static_cast<int>(std::max(1L, sysconf(_SC_NPROCESSORS_ONLN))) - 1;
  Fragment out;
  UsHistogram chimera_hist;
  UsHistogram cyclictest_hist;
  std::vector<std::uint32_t> chimera_ns;
  std::uint64_t cyclictest_cycles = 0;
  auto& halves = out.details()["halves"];
  for (int half = 0; half < 2; ++half) {
    const int cpu = half == 0 ? last_cpu : 0;
    const std::string json =
        fmt::format("{}/cyclictest_{}.json", args.samples_dir.empty() ? "/tmp" : args.samples_dir, half);
    const std::uint64_t chimera_before = chimera_hist.total();
    const std::uint64_t cycles_before = cyclictest_cycles;
    std::int64_t first = 0;
    Half h = run_half(cpu, seconds, cyclictest, json, chimera_hist, chimera_ns, first);
    if (h.ok && !read_cyclictest(json, cyclictest_hist, cyclictest_cycles)) {
      h.ok = false;
      h.error = "could not read cyclictest's results " + json;
    }
    nlohmann::json d{{"cpu", cpu}, {"seconds", seconds}};
    if (!h.ok) {
      d["error"] = h.error;
      halves.push_back(d);
      std::fprintf(stderr, "release_latency: %s\n", h.error.c_str());
      (void)out.write(args);
      return 1;
    }
    d["chimera_samples"] = chimera_hist.total() - chimera_before;
    d["cyclictest_samples"] = cyclictest_cycles - cycles_before;
    d["framework_stats_ns"] = {{"cycles", h.framework.stats.cycles},
                               {"missed", h.framework.stats.missed},
                               {"p50", h.framework.stats.latency_p50_ns},
                               {"p99", h.framework.stats.latency_p99_ns},
                               {"max", h.framework.stats.latency_max_ns}};
    halves.push_back(d);
  }
  UsHistogram control_first;
  UsHistogram control_second;
  const int control_seconds = args.quick ? 3 : 20;
  if (run_control(control_seconds, last_cpu, cyclictest, args.samples_dir.empty() ? "/tmp" : args.samples_dir,
                  control_first, control_second)) {
    auto& c = out.details()["control"];
    c["what"] = "cyclictest against cyclictest, same CPU, half a period apart, one pair per CPU at once";
    c["seconds"] = control_seconds;
    c["first"] = describe(control_first);
    c["second"] = describe(control_second);
    out.result("release_latency_control_p50_ratio",
               control_first.percentile_ns(0.50) / control_second.percentile_ns(0.50));
    out.result("release_latency_control_p99_ratio",
               control_first.percentile_ns(0.99) / control_second.percentile_ns(0.99));
  }
  out.details()["chimera"] = describe(chimera_hist);
  out.details()["cyclictest"] = describe(cyclictest_hist);
  out.details()["cyclictest"]["cycles"] = cyclictest_cycles;
  out.details()["method"] =
      "simultaneous, 1 kHz, SCHED_FIFO 80, on the same CPU with cyclictest's wake-ups half a period after "
      "Chimera's (--secaligned), last CPU then CPU 0; 1 us bins, interpolated percentiles";
  const double c50 = chimera_hist.percentile_ns(0.50);
  const double c99 = chimera_hist.percentile_ns(0.99);
  const double t50 = cyclictest_hist.percentile_ns(0.50);
  const double t99 = cyclictest_hist.percentile_ns(0.99);
  out.result("release_latency_ns_p50", c50);
  out.result("release_latency_ns_p99", c99);
  out.result("cyclictest_latency_ns_p50", t50);
  out.result("cyclictest_latency_ns_p99", t99);
  if (t50 > 0) out.result("release_latency_p50_ratio", c50 / t50);
  if (t99 > 0) out.result("release_latency_p99_ratio", c99 / t99);
  out.samples(args, "release_chimera", chimera_ns);
  out.samples(args, "release_cyclictest", cyclictest_hist.as_samples());
  return out.write(args);
}
