#pragma once
// The release policy, written once: plain functions of time that both executives call, the real
// one with CLOCK_MONOTONIC times, the virtual one with simulated times, so that the virtual
// clock stays an oracle for the real one (docs/scheduling.md). Each is tested on its own in
// tests/unit/exec/release_policy_test.cpp. All are real-time safe.
//
//   the grid          periodic releases at whole multiples of the period, from time 0
//   late releases     what a task that comes back late does with the releases that passed
//   the same-rate     when a consumer waits for a producer of the same period, and how long
//   rule
//   a switch's        the cycle boundary a commit goes at
//   commit
//   the wake lead     how early a thread that waits for a producer on another CPU wakes
// The sporadic server's budget is sporadic_server.hpp; a task's trigger variable is the Task's.

#include <algorithm>
#include <cstdint>

#include "chimera/config/subsystem.hpp"

namespace chimera::release_policy {

/// The index k of the first release k * period at or after `t` (t >= 0, period > 0): where a task
/// turning on at `t` joins the grid.
constexpr std::int64_t first_release_index(std::int64_t t, std::int64_t period) noexcept {
  return (t + period - 1) / period;
}

/// The first grid point of `period` strictly after `t`: the cycle boundary a switch commits at
/// (t is now plus the time the commit needs to be posted, on the real clock).
constexpr std::int64_t next_boundary_after(std::int64_t t, std::int64_t period) noexcept {
  return (t / period + 1) * period;
}

/// What a task whose next release is at `next_release` does, finding itself at `now`.
struct LateReleases {
  std::uint64_t skipped = 0;      // releases it does not run, each a missed deadline
  std::int64_t next_release = 0;  // the release it runs next (later than now if all passed)
};

/// Under `late: skip`, the releases whose absolute deadline has already passed are not worth
/// starting: they are skipped, and the task goes on at the first whose deadline is still ahead.
/// Under `late: run` nothing is skipped: the late releases run one after another, late, and the
/// grid holds. `relative_deadline` 0 means none (nothing is ever skipped). Times in one unit.
constexpr LateReleases late_releases(LatePolicy late, std::int64_t next_release, std::int64_t now, std::int64_t period,
                                     std::int64_t relative_deadline) noexcept {
  if (late != LatePolicy::kSkip || relative_deadline <= 0) return {0, next_release};
  // The releases r = next_release + j * period with r + relative_deadline < now, counted at once
  // (a loop would take as long as the stall divided by the period).
  const std::int64_t past = now - relative_deadline - next_release;
  if (past <= 0) return {0, next_release};
  const std::int64_t n = (past + period - 1) / period;
  return {static_cast<std::uint64_t>(n), next_release + n * period};
}

/// The same-rate rule (analysis/release_order.hpp): a consumer's job of release `release` waits for a
/// same-period producer that is ON (or joining at or before that release), has not completed
/// that release, and will run it next: its next release to run is that one (or its last
/// completed is the one before, its next not published yet). A producer that turned on later,
/// skipped that release, or is behind (it still has an earlier release to run: it is catching
/// up after a stall, or is stalled itself) is not waited for: the consumer runs at once with the
/// producer's latest value. Waiting for a producer that is behind would cost its whole backlog,
/// and with several consumers on one thread one stall would cascade (docs/scheduling.md, "After
/// a stall"). Releases in one unit (index or ns).
constexpr bool waits_for_producer(bool producer_on, bool producer_completed_it, bool producer_completed_previous,
                                  std::int64_t producer_next, std::int64_t release) noexcept {
  if (!producer_on || producer_completed_it || producer_next < 0 || producer_next > release) return false;
  return producer_next == release || producer_completed_previous;
}

/// Whether the producer is behind the consumer's release: ON, with an earlier release still to
/// run before this one. The consumer then runs without this release's value (counted in its
/// order_timeouts, as a wait that gave up is). Arguments as for waits_for_producer.
constexpr bool producer_behind(bool producer_on, bool producer_completed_it, bool producer_completed_previous,
                               std::int64_t producer_next, std::int64_t release) noexcept {
  return producer_on && !producer_completed_it && producer_next >= 0 && producer_next < release &&
         !producer_completed_previous;
}

/// How long at most a consumer waits for its producers: until half its relative deadline after
/// the wait starts (or after the release, if it starts before it). Counted from the start of the
/// wait so that, when tasks catch up after a stall and every release is already in the past, the
/// order still holds; bounded so that a stuck producer cannot hold a consumer hostage.
constexpr std::int64_t producer_wait_until(std::int64_t release, std::int64_t wait_start,
                                           std::int64_t relative_deadline) noexcept {
  return std::max(release, wait_start) + relative_deadline / 2;
}

/// The longest a thread wakes before its release (see wake_lead): about the p99 of a timer's
/// wake-up latency on the 2-CPU VMs this runs on (bench/results/latest.md, cyclictest).
inline constexpr std::int64_t kMaxWakeLeadNs = 50'000;

/// How early a thread wakes for a release whose first job waits for a same-period producer on
/// another CPU (it then spins to the release): that job starts when both the producer's CPU and
/// its own have woken, so each CPU's timer latency would count, the worse of the two at every
/// release. Woken early, only the producer's does. Capped at a twentieth of the period, which
/// is what the spin costs the thread's CPU at most; 0 for a thread that waits for nothing on
/// another CPU (it would spin for nothing).
constexpr std::int64_t wake_lead(bool waits_on_another_cpu, std::int64_t period) noexcept {
  if (!waits_on_another_cpu || period <= 0) return 0;
  return std::min(kMaxWakeLeadNs, period / 20);
}

}  // namespace chimera::release_policy
