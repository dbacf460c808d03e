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

std::string_view reliability_name(DdsReliability r) {
  switch (r) {
    case DdsReliability::kReliable: return "reliable";
    case DdsReliability::kBestEffort: return "best_effort";
  }
  return "?";
}

std::string_view durability_name(DdsDurability d) {
  switch (d) {
    case DdsDurability::kVolatile: return "volatile";
    case DdsDurability::kTransientLocal: return "transient_local";
  }
  return "?";
}

}  // namespace chimera
