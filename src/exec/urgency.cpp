#include "urgency.hpp"

#include <tuple>

namespace chimera {

bool more_urgent(SchedulerKind policy, const TaskUrgency& a, const JobUrgency& ja, const TaskUrgency& b,
                 const JobUrgency& jb) noexcept {
  // Background work never delays a task that has a guarantee to keep.
  if (a.background != b.background) return b.background;
  if (a.background) return std::tie(ja.release_ns, a.index) < std::tie(jb.release_ns, b.index);
  switch (policy) {
    case SchedulerKind::kRm: return std::tie(a.period_ns, a.rank, a.index) < std::tie(b.period_ns, b.rank, b.index);
    case SchedulerKind::kDm:
      return std::tie(a.deadline_ns, a.period_ns, a.rank, a.index) <
             std::tie(b.deadline_ns, b.period_ns, b.rank, b.index);
    case SchedulerKind::kEdf:
      return std::tie(ja.deadline_ns, ja.release_ns, a.rank, a.index) <
             std::tie(jb.deadline_ns, jb.release_ns, b.rank, b.index);
    case SchedulerKind::kMuf: {
      // A critical task always beats a non-critical one; a higher user priority wins a tie.
      const int ca = a.critical ? 0 : 1;
      const int cb = b.critical ? 0 : 1;
      const int ua = -a.user_priority;
      const int ub = -b.user_priority;
      return std::tie(ca, ja.deadline_ns, ua, ja.release_ns, a.rank, a.index) <
             std::tie(cb, jb.deadline_ns, ub, jb.release_ns, b.rank, b.index);
    }
  }
  return false;
}

}  // namespace chimera
