#include "chimera/config/subsystem.hpp"

namespace chimera {

std::string_view scheduler_name(SchedulerKind s) {
  switch (s) {
    case SchedulerKind::kRm: return "rm";
    case SchedulerKind::kDm: return "dm";
    case SchedulerKind::kEdf: return "edf";
    case SchedulerKind::kMuf: return "muf";
  }
  return "?";
}

std::string_view criticality_name(Criticality c) {
  switch (c) {
    case Criticality::kHard: return "hard";
    case Criticality::kSoft: return "soft";
  }
  return "?";
}

std::string_view late_policy_name(LatePolicy p) {
  switch (p) {
    case LatePolicy::kRun: return "run";
    case LatePolicy::kSkip: return "skip";
  }
  return "?";
}

}  // namespace chimera
