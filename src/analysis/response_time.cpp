#include "chimera/analysis/response_time.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

#include "chimera/analysis/utilisation.hpp"
#include "detail/wide.hpp"

namespace chimera::analysis {
namespace {

using detail::Wide;

// Past this a response time means nothing (292 years would overflow first); stop there.
constexpr std::int64_t kHorizonNs = std::numeric_limits<std::int64_t>::max() / 4;
// Fixed-point steps over all jobs of one task; each step adds at least one C of some task.
constexpr long kMaxSteps = 20'000'000;
constexpr int kMaxJobs = 1'000'000;

Wide ceil_div(Wide a, Wide b) { return (a + b - 1) / b; }

// Interference in a window of length w: sum over j of ceil((w + J_j) / T_j) C_j (a task with
// release jitter J_j can bring one more job into the window; Audsley et al. 1993).
Wide interference_in(std::span<const Demand> tasks, Wide w) {
  Wide sum = 0;
  for (const auto& t : tasks) sum += ceil_div(w + t.j_ns, t.t_ns) * t.c_ns;
  return sum;
}

std::int64_t priority_key(const TaskModel& t, SchedulerKind scheduler) {
  return scheduler == SchedulerKind::kDm ? relative_deadline(t) : t.period_ns;
}

}  // namespace

ResponseTime response_time(const Demand& task, std::span<const Demand> interference) {
  ResponseTime r;
  std::vector<Demand> level(interference.begin(), interference.end());
  level.push_back(task);
  r.level_utilisation = utilisation(level);
  if (!utilisation_at_most_one(level)) {
    r.outcome = RtaOutcome::kOverloaded;
    return r;
  }

  // Job q (from 0) of the level-i busy period that starts at the critical instant completes at
  // the least w with w = (q+1) C + interference(w); its response time, from its release, is
  // w - q T + J (its own jitter: it became ready J after its release). The busy period ends with
  // the first job that completes before the task's next job can become ready (Tindell, Burns and
  // Wellings 1994).
  Wide w = task.c_ns + std::accumulate(interference.begin(), interference.end(), Wide{0},
                                       [](Wide s, const Demand& d) { return s + d.c_ns; });
  Wide worst = 0;
  bool missed = false;
  long steps = 0;
  for (int q = 0; q < kMaxJobs; ++q) {
    const Wide own = static_cast<Wide>(q + 1) * task.c_ns;
    for (;;) {
      const Wide next = own + interference_in(interference, w);
      if (next == w) break;
      w = next;
      if (++steps > kMaxSteps || w > kHorizonNs) {
        r.jobs = q + 1;
        r.outcome = missed ? RtaOutcome::kMisses : RtaOutcome::kGaveUp;
        r.response_ns = static_cast<std::int64_t>(std::max(worst, w - static_cast<Wide>(q) * task.t_ns + task.j_ns));
        return r;
      }
    }
    const Wide response = w - static_cast<Wide>(q) * task.t_ns + task.j_ns;
    worst = std::max(worst, response);
    missed = missed || response > task.d_ns;
    r.jobs = q + 1;
    if (w + task.j_ns <= static_cast<Wide>(q + 1) * task.t_ns) {
      r.outcome = missed ? RtaOutcome::kMisses : RtaOutcome::kMeets;
      r.response_ns = static_cast<std::int64_t>(worst);
      r.exact = true;
      return r;
    }
    w += task.c_ns;  // job q+1 cannot complete before job q plus one more C
  }
  r.outcome = missed ? RtaOutcome::kMisses : RtaOutcome::kGaveUp;
  r.response_ns = static_cast<std::int64_t>(worst);
  return r;
}

double response_time_upper_bound(std::int64_t c_ns, double interference_utilisation, double interference_weighted_c) {
  if (interference_utilisation >= 1.0) return std::numeric_limits<double>::infinity();
  return (static_cast<double>(c_ns) + interference_weighted_c) / (1.0 - interference_utilisation);
}

std::vector<int> fixed_priority_ranks(std::span<const TaskModel> tasks, SchedulerKind scheduler) {
  std::vector<std::int64_t> keys;
  for (const auto& t : tasks)
    if (!is_background(t)) keys.push_back(priority_key(t, scheduler));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<int> ranks;
  ranks.reserve(tasks.size());
  for (const auto& t : tasks) {
    if (is_background(t)) {
      ranks.push_back(-1);
      continue;
    }
    const auto at = std::lower_bound(keys.begin(), keys.end(), priority_key(t, scheduler));
    ranks.push_back(static_cast<int>(at - keys.begin()));
  }
  return ranks;
}

std::vector<std::size_t> fixed_priority_order(std::span<const TaskModel> tasks, SchedulerKind scheduler) {
  const auto ranks = fixed_priority_ranks(tasks, scheduler);
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < tasks.size(); ++i)
    if (ranks[i] >= 0) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (ranks[a] != ranks[b]) return ranks[a] < ranks[b];
    return tasks[a].file_index < tasks[b].file_index;
  });
  return order;
}

}  // namespace chimera::analysis
