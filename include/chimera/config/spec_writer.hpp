#pragma once
// The subsystem model written back as a subsystem file (contract section 1): what the live
// assembly's `save` writes, and what `add` extends to check a new task exactly as the loader
// checks a file. load_subsystem_text() of the text gives back the same model.

#include <string>

#include "chimera/config/subsystem.hpp"

namespace chimera {

/// `spec` as YAML that load_subsystem_text() reads back to an equal model: every key the model
/// holds (defaults that the loader would fill in are left out), durations exact. Not real-time safe.
std::string write_subsystem_yaml(const SubsystemSpec& spec);

}  // namespace chimera
