#pragma once
// Checks what a module says about itself before anyone relies on it: the plugin loader refuses
// a library whose modules declare ports or parameters badly, with a message naming the flaw.
// Private to src/.

#include "chimera/core/result.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::module_detail {

/// Calls the module's declare() with its default parameters (catching what it throws) and
/// checks the result: a module name and port and parameter names that are identifiers, no name
/// declared twice, sizes that are at least 1 and name one of the module's own const ports,
/// out-consts with a value. Errors (Errc::kInvalidInput) read "module NAME: problem".
/// Not real-time safe.
Result<void> check_module(const ModuleInfo& info);

}  // namespace chimera::module_detail
