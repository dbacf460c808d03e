#include "chimera/analysis/processor_demand.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "chimera/analysis/utilisation.hpp"
#include "detail/wide.hpp"

namespace chimera::analysis {
namespace {

using detail::Wide;
constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kHorizonNs = kMax / 4;
constexpr long kMaxSteps = 20'000'000;

// The deadline relative to the latest moment the job can become ready: a job whose release can be
// J late must finish within D - J of becoming ready. With it, h(t) is the demand of jobs with
// jitter (Spuri 1996), and every test below holds as for a task without jitter. 0 when J >= D:
// such a job cannot be guaranteed, and h(0) > 0 says so.
std::int64_t ready_deadline(const Demand& t) { return std::max<std::int64_t>(t.d_ns - t.j_ns, 0); }

// The longest busy period: the least L > 0 with L = sum ceil((L + J) / T) C (a task with jitter
// can bring a job J early into the window). Finite when U <= 1. A missed deadline comes first
// within one, so no interval longer than L needs checking.
std::optional<std::int64_t> busy_period(std::span<const Demand> tasks) {
  Wide w = 0;
  for (const auto& t : tasks) w += t.c_ns;
  for (long step = 0; step < kMaxSteps && w <= kHorizonNs; ++step) {
    Wide next = 0;
    for (const auto& t : tasks) next += (w + t.j_ns + t.t_ns - 1) / t.t_ns * t.c_ns;
    if (next == w) return static_cast<std::int64_t>(w);
    w = next;
  }
  return std::nullopt;
}

// George, Rivierre and Spuri (1996): for U < 1 no deadline can be missed first after
// max(D_max, sum (T - D) U / (1 - U)). Long double, then rounded up generously: a longer
// interval only costs time, a shorter one would be wrong.
std::optional<std::int64_t> george_bound(std::span<const Demand> tasks, double u) {
  const long double slack = 1.0L - static_cast<long double>(u);
  if (slack < 1e-9L) return std::nullopt;
  long double sum = 0;
  std::int64_t d_max = 0;
  for (const auto& t : tasks) {
    sum += static_cast<long double>(t.t_ns - ready_deadline(t)) * static_cast<long double>(t.c_ns) /
           static_cast<long double>(t.t_ns);
    d_max = std::max(d_max, ready_deadline(t));
  }
  const long double bound = std::ceil(sum / slack * (1.0L + 1e-6L)) + 1.0L;
  if (bound > static_cast<long double>(kHorizonNs)) return std::nullopt;
  return std::max(d_max, static_cast<std::int64_t>(bound));
}

// The latest absolute deadline k T + D strictly before t, if any.
std::optional<std::int64_t> deadline_before(std::span<const Demand> tasks, std::int64_t t) {
  std::optional<std::int64_t> latest;
  for (const auto& x : tasks) {
    const std::int64_t dx = ready_deadline(x);
    if (t <= dx) continue;
    const std::int64_t d = (t - dx - 1) / x.t_ns * x.t_ns + dx;
    if (!latest || d > *latest) latest = d;
  }
  return latest;
}

}  // namespace

std::optional<std::int64_t> longest_busy_period(std::span<const Demand> tasks) {
  if (tasks.empty()) return 0;
  if (!utilisation_at_most_one(tasks)) return std::nullopt;
  return busy_period(tasks);
}

std::int64_t processor_demand(std::span<const Demand> tasks, std::int64_t t) {
  Wide h = 0;
  for (const auto& x : tasks)
    if (t >= ready_deadline(x)) h += static_cast<Wide>((t - ready_deadline(x)) / x.t_ns + 1) * x.c_ns;
  return h > kMax ? kMax : static_cast<std::int64_t>(h);
}

EdfTest edf_test(std::span<const Demand> tasks) {
  EdfTest r;
  r.utilisation = utilisation(tasks);
  if (!utilisation_at_most_one(tasks)) {
    r.outcome = EdfOutcome::kOverloaded;
    return r;
  }
  r.utilisation_decides =
      std::all_of(tasks.begin(), tasks.end(), [](const Demand& t) { return ready_deadline(t) >= t.t_ns; });
  if (r.utilisation_decides || tasks.empty()) {
    r.outcome = EdfOutcome::kFeasible;
    return r;
  }

  // Deadlines after L cannot be the first ones missed: check those before it.
  const auto lb = busy_period(tasks);
  const auto la = george_bound(tasks, r.utilisation);
  if (!lb && !la) return r;  // kGaveUp
  r.bound_ns = lb && la ? std::min(*lb, *la) : (lb ? *lb : *la);

  // QPA: from the latest deadline before L downwards; h(t) < t lets it jump to h(t) at once.
  std::int64_t d_min = kMax;
  for (const auto& t : tasks) d_min = std::min(d_min, ready_deadline(t));
  auto t = deadline_before(tasks, r.bound_ns);
  while (t) {
    if (++r.points > kMaxSteps) return r;  // kGaveUp
    const std::int64_t h = processor_demand(tasks, *t);
    if (h > *t) {
      r.outcome = EdfOutcome::kDemandExceeded;
      r.interval_ns = *t;
      r.demand_ns = h;
      return r;
    }
    if (h <= d_min) break;
    t = h < *t ? std::optional<std::int64_t>(h) : deadline_before(tasks, *t);
  }
  r.outcome = EdfOutcome::kFeasible;
  return r;
}

}  // namespace chimera::analysis
