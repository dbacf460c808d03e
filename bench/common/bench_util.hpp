#pragma once
// What the benchmark programs share: the command line every program takes (--out FILE,
// --samples-dir DIR, --quick), a JSON fragment of results that bench/run.py merges, sample files
// for the plots, percentiles, CPU pinning and a TSC stopwatch for operations of a few
// nanoseconds. Not part of the library: none of this runs in a subsystem.

#include <pthread.h>
#include <sched.h>
#include <x86intrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "chimera/exec/clock.hpp"

namespace chimera::bench {

/// The command line of every benchmark program.
struct Args {
  std::string out;          // JSON fragment: {"results": {...}, "details": {...}, "samples": {...}}
  std::string samples_dir;  // where sample files for the plots go ("" = none)
  bool quick = false;       // make bench-quick: fewer samples, shorter runs
  std::vector<std::string> rest;

  static Args parse(int argc, char** argv) {
    Args a;
    for (int i = 1; i < argc; ++i) {
      const std::string_view s = argv[i];
      if (s == "--out" && i + 1 < argc) {
        a.out = argv[++i];
      } else if (s == "--samples-dir" && i + 1 < argc) {
        a.samples_dir = argv[++i];
      } else if (s == "--quick") {
        a.quick = true;
      } else {
        a.rest.emplace_back(s);
      }
    }
    return a;
  }
};

/// Results of one program. Keys of `results` are the keys; a figure that could not be
/// measured is simply not set (never zero). `details` holds supporting figures for the report.
/// nlohmann::json (std::map inside) keeps references to members valid while others are added.
class Fragment {
 public:
  void result(const std::string& key, double value) {
    if (std::isfinite(value)) doc_["results"][key] = value;
  }
  nlohmann::json& details() { return doc_["details"]; }
  void note(const std::string& text) { doc_["notes"].push_back(text); }

  /// Saves `ns` as a sample file (little-endian uint32 nanoseconds) named `name`.bin and lists
  /// it under "samples", so that the report can plot the distribution.
  void samples(const Args& args, const std::string& name, const std::vector<std::uint32_t>& ns) {
    if (args.samples_dir.empty() || ns.empty()) return;
    const std::string path = args.samples_dir + "/" + name + ".bin";
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(ns.data()),  // NOLINT(*-reinterpret-cast): raw bytes out
            static_cast<std::streamsize>(ns.size() * sizeof(std::uint32_t)));
    if (f) doc_["samples"][name] = path;
  }

  /// Writes the fragment to args.out (or stdout). Returns the process exit code.
  [[nodiscard]] int write(const Args& args) const {
    const std::string text = doc_.dump(2) + "\n";
    if (args.out.empty()) {
      std::fputs(text.c_str(), stdout);
      return 0;
    }
    std::ofstream f(args.out, std::ios::trunc);
    f << text;
    if (!f) {
      std::fprintf(stderr, "cannot write %s\n", args.out.c_str());
      return 1;
    }
    return 0;
  }

 private:
  nlohmann::json doc_ = nlohmann::json::object();
};

/// The value below which `fraction` of `sorted` lies (nearest rank). `sorted` must not be empty.
template <class T>
double percentile_sorted(const std::vector<T>& sorted, double fraction) {
  const auto n = sorted.size();
  auto rank = static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(n)));
  rank = std::clamp<std::size_t>(rank, 1, n);
  return static_cast<double>(sorted[rank - 1]);
}

/// p50, p99, p99.9, max and mean of `v` (sorted in place), as a JSON object.
template <class T>
nlohmann::json summary(std::vector<T>& v) {
  nlohmann::json j = nlohmann::json::object();
  if (v.empty()) return j;
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (const T x : v) sum += static_cast<double>(x);
  j["count"] = v.size();
  j["min"] = static_cast<double>(v.front());
  j["p50"] = percentile_sorted(v, 0.50);
  j["p90"] = percentile_sorted(v, 0.90);
  j["p99"] = percentile_sorted(v, 0.99);
  j["p999"] = percentile_sorted(v, 0.999);
  j["max"] = static_cast<double>(v.back());
  j["mean"] = sum / static_cast<double>(v.size());
  return j;
}

// The framework's own clock reading, so that a benchmark that also includes the subsystem's
// headers (which declare chimera::monotonic_ns) has one name, not two.
using chimera::monotonic_ns;

/// Pins the calling thread to one CPU. False if the system refuses.
inline bool pin_to_cpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<unsigned>(cpu), &set);
  return pthread_setaffinity_np(pthread_self(), sizeof(set), &set) == 0;
}

/// A stopwatch on the time stamp counter, for operations far shorter than a clock_gettime call:
/// lfence keeps the operation inside the two reads. ns_per_tick is calibrated against
/// CLOCK_MONOTONIC; overhead_ticks (an empty interval's median) is subtracted from every interval.
class TscClock {
 public:
  static TscClock calibrate() {
    TscClock c;
    const std::int64_t t0 = monotonic_ns();
    const std::uint64_t r0 = stamp();
    while (monotonic_ns() - t0 < 100'000'000) {
    }
    const std::int64_t t1 = monotonic_ns();
    const std::uint64_t r1 = stamp();
    c.ns_per_tick_ = static_cast<double>(t1 - t0) / static_cast<double>(r1 - r0);
    std::vector<std::uint64_t> empty(10001);
    for (auto& e : empty) {
      const std::uint64_t a = stamp();
      const std::uint64_t b = stamp();
      e = b - a;
    }
    std::nth_element(empty.begin(), empty.begin() + 5000, empty.end());
    c.overhead_ticks_ = empty[5000];
    return c;
  }

  static std::uint64_t stamp() {
    _mm_lfence();  // earlier instructions finish before the counter is read
    const std::uint64_t t = __rdtsc();
    _mm_lfence();  // and later ones start after it
    return t;
  }

  /// Nanoseconds of an interval measured by two stamp() calls, less the stopwatch's own cost.
  [[nodiscard]] std::uint32_t ns(std::uint64_t begin, std::uint64_t end) const {
    const std::uint64_t ticks = end - begin > overhead_ticks_ ? end - begin - overhead_ticks_ : 0;
    const double v = static_cast<double>(ticks) * ns_per_tick_;
    return v > 4e9 ? 4'000'000'000U : static_cast<std::uint32_t>(v);
  }
  [[nodiscard]] double ns_per_tick() const { return ns_per_tick_; }
  [[nodiscard]] double overhead_ns() const { return static_cast<double>(overhead_ticks_) * ns_per_tick_; }

 private:
  double ns_per_tick_ = 1.0;
  std::uint64_t overhead_ticks_ = 0;
};

}  // namespace chimera::bench
