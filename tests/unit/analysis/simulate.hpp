#pragma once
// A brute-force oracle for the analysis tests: one processor, every task released at 0 and then
// strictly periodically, time in whole units, jobs of one task in order. It is as simple as it can
// be, so that it can check the clever tests (RTA, QPA) on sets nobody worked out by hand.

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <ostream>
#include <random>
#include <vector>

#include "chimera/analysis/task_model.hpp"
#include "chimera/analysis/utilisation.hpp"

namespace chimera::analysis {

/// How GoogleTest prints a task in a failure message: "(C 2, T 5, D 4)".
// NOLINTNEXTLINE(readability-identifier-naming): the name GoogleTest looks for
inline void PrintTo(const Demand& d, std::ostream* os) {
  *os << "(C " << d.c_ns << ", T " << d.t_ns << ", D " << d.d_ns << ")";
}

}  // namespace chimera::analysis

namespace chimera::analysis::test {

enum class Policy { kFixedPriority, kEdf };

struct SimResult {
  std::vector<std::int64_t> worst_response;  // per task
  bool all_met = true;
};

/// Runs `tasks` for `horizon` units (one hyperperiod plus the longest deadline is enough for a
/// synchronous periodic set). Fixed priority: index order is priority order (0 highest). EDF:
/// earliest absolute deadline, ties to the lower index.
inline SimResult simulate(const std::vector<Demand>& tasks, Policy policy, std::int64_t horizon) {
  struct Job {
    std::size_t task;
    std::int64_t release;
    std::int64_t deadline;
    std::int64_t left;
  };
  SimResult r;
  r.worst_response.assign(tasks.size(), 0);
  std::vector<Job> ready;
  for (std::int64_t now = 0; now < horizon; ++now) {
    for (std::size_t i = 0; i < tasks.size(); ++i)
      if (now % tasks[i].t_ns == 0) ready.push_back(Job{i, now, now + tasks[i].d_ns, tasks[i].c_ns});
    // The earliest unfinished job of each task is the only one that may run.
    Job* pick = nullptr;
    for (auto& j : ready) {
      const bool first_of_task = std::none_of(ready.begin(), ready.end(),
                                              [&](const Job& o) { return o.task == j.task && o.release < j.release; });
      if (!first_of_task) continue;
      const bool better = pick == nullptr ||
                          (policy == Policy::kFixedPriority ? j.task < pick->task
                                                            : (j.deadline < pick->deadline ||
                                                               (j.deadline == pick->deadline && j.task < pick->task)));
      if (better) pick = &j;
    }
    if (pick == nullptr) continue;
    if (--pick->left == 0) {
      const std::int64_t response = now + 1 - pick->release;
      r.worst_response[pick->task] = std::max(r.worst_response[pick->task], response);
      if (now + 1 > pick->deadline) r.all_met = false;
      ready.erase(ready.begin() + (pick - ready.data()));
    }
  }
  // A job still unfinished at the end past its deadline is a miss too.
  for (const auto& j : ready)
    if (j.deadline < horizon) r.all_met = false;
  return r;
}

inline std::int64_t hyperperiod(const std::vector<Demand>& tasks) {
  std::int64_t h = 1;
  for (const auto& t : tasks) h = std::lcm(h, t.t_ns);
  return h;
}

/// Task sets to compare a test with simulate(): `tries` draws from a fixed seed (the same sets
/// every run) of 2 to 5 tasks, T from 2 to max_period, C from 1 to T/2, D from C to T plus
/// `late_percent` of T; kept are the sets with U <= 1 and a hyperperiod of at most 20,000.
inline std::vector<std::vector<Demand>> generated_sets(unsigned seed, int tries, std::int64_t max_period,
                                                       std::int64_t late_percent) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> count(2, 5);
  std::uniform_int_distribution<std::int64_t> period(2, max_period);
  std::vector<std::vector<Demand>> sets;
  for (int set = 0; set < tries; ++set) {
    std::vector<Demand> tasks;
    const int n = count(random);
    for (int i = 0; i < n; ++i) {
      const std::int64_t t = period(random);
      const std::int64_t c = std::uniform_int_distribution<std::int64_t>(1, std::max<std::int64_t>(1, t / 2))(random);
      const std::int64_t d = std::uniform_int_distribution<std::int64_t>(c, t + t * late_percent / 100)(random);
      tasks.push_back(Demand{c, t, d});
    }
    if (utilisation_at_most_one(tasks) && hyperperiod(tasks) <= 20'000) sets.push_back(std::move(tasks));
  }
  return sets;
}

}  // namespace chimera::analysis::test
