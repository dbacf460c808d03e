#include "chimera/control/stats_json.hpp"

#include <cerrno>
#include <fstream>
#include <system_error>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace chimera {

std::string stats_json(std::span<const TaskSnapshot> tasks, ClockKind clock, std::uint64_t switches, bool rt_check,
                       JsonLayout layout) {
  // ordered_json keeps the tasks in file order, which is how people read them.
  using Json = nlohmann::ordered_json;
  Json per_task = Json::object();
  auto histogram = [](const std::vector<std::pair<std::int64_t, std::uint64_t>>& buckets) {
    Json out = Json::array();
    for (const auto& [upper, count] : buckets) out.push_back(Json::array({upper, count}));
    return out;
  };
  // On the virtual clock a job takes its simulated time (virtual_exec plus what its module
  // charged) and exec_ns is that time; on the real clock it is the host's.
  const char* exec_clock = clock == ClockKind::kVirtual ? "virtual" : "host";
  for (const auto& t : tasks) {
    const auto& s = t.stats;
    per_task[t.name] = Json{
        {"module", t.module},
        {"state", std::string(state_name(t.state))},
        {"cpu", t.cpu},
        {"period_ns", t.period_ns},
        {"cycles", s.cycles},
        {"missed", s.missed},
        {"overruns", s.overruns},
        {"skipped", s.skipped},
        {"order_timeouts", s.order_timeouts},
        {"rt_violations", s.rt_violations},  // allocations in on/cycle/off/sync; counted only with rt_check
        {"exec_ns",
         Json{{"mean", s.exec_mean_ns}, {"p50", s.exec_p50_ns}, {"p99", s.exec_p99_ns}, {"max", s.exec_max_ns}}},
        // Which clock exec_ns (and its histogram) is in, and what the cycles took on the host.
        {"exec_clock", exec_clock},
        {"host_exec_ns", Json{{"mean", s.host_exec_mean_ns}, {"max", s.host_exec_max_ns}}},
        {"latency_ns", Json{{"p50", s.latency_p50_ns}, {"p99", s.latency_p99_ns}, {"max", s.latency_max_ns}}},
        {"response_ns", Json{{"p99", s.response_p99_ns}, {"max", s.response_max_ns}}},
        // The profiles: [bucket upper bound in ns, count] for each bucket that holds records.
        {"histograms", Json{{"exec_ns", histogram(s.exec_histogram)}, {"latency_ns", histogram(s.latency_histogram)}}},
    };
  }
  const Json doc{
      {"clock", clock == ClockKind::kVirtual ? "virtual" : "real"},
      {"exec_clock", exec_clock},
      {"switches", switches},
      {"rt_check", rt_check},
      {"tasks", std::move(per_task)},
  };
  return layout == JsonLayout::kIndented ? doc.dump(2) + "\n" : doc.dump();
}

Result<void> write_stats_json(const std::string& path, std::span<const TaskSnapshot> tasks, ClockKind clock,
                              std::uint64_t switches, bool rt_check) {
  std::ofstream out(path, std::ios::trunc);
  if (!out)
    return make_error(Errc::kSystem, fmt::format("{}: cannot write: {}", path, std::generic_category().message(errno)));
  out << stats_json(tasks, clock, switches, rt_check);
  out.close();
  if (!out) return make_error(Errc::kSystem, fmt::format("{}: write failed", path));
  return {};
}

}  // namespace chimera
