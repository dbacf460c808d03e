#pragma once
// The JSON documents of the control API that describe rather than command: the module library
// (GET /api/modules, the page's hypermedia library) and the subsystem's model (GET
// /api/subsystem: its tasks with their ports bound, its configurations verified), from which the
// page draws the canvas. Not real-time safe.

#include <vector>

#include <nlohmann/json.hpp>

#include "chimera/config/verify.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::net {

/// Every module of `registry`, sorted by name: summary, documentation, ports and parameters as
/// the default parameters declare them (sizes stay symbolic: "ndof", "6*ndof", "any").
nlohmann::json module_library_json(const Registry& registry);

/// The subsystem as the live assembly has it now: every task with its ports bound to variables
/// (after renames), every configuration with its tasks and its verdict (the violations of the
/// paper's equations 1 and 2 and of the size rule), the one on now. Call it under the gate.
nlohmann::json subsystem_model_json(const Subsystem& subsystem);

/// The example subsystem files the program was built with (examples/): name, title and text.
nlohmann::json examples_json();

/// Violations as the replies of define and verify give them: rule, variable, tasks, reason.
nlohmann::json violations_json(const std::vector<Violation>& violations);

}  // namespace chimera::net
