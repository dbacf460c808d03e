#pragma once
// One task's profile for the operator (`stats TASK`): its timing figures and text histograms of
// its execution times and release latencies, gathered by the framework without allocation.

#include <string>

#include "chimera/control/subsystem.hpp"

namespace chimera {

/// Lines ending in '\n'. Not real-time safe.
std::string task_profile(const TaskSnapshot& task);

}  // namespace chimera
