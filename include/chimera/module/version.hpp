#pragma once
// Which Chimera this is: the version and the module ABI that module libraries must be built for.

#include <string>

namespace chimera {

/// "chimera 0.1.0 (module ABI 3f2a19c0d41b77e2)". Not real-time safe.
std::string version_text();

}  // namespace chimera
