// Fuzz target: the subsystem-file loader and verification (chimera verify's path), on YAML text.
// Whatever the text, loading must end in a spec or one "file:line: key: problem" message, and
// verification of a loaded spec in a list of violations: never a crash, a hang or a leak.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "chimera/core/invariant.hpp"
#include "chimera/module/registry.hpp"
#include "fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = chimera::fuzz::as_text(data, size);
  constexpr const char* kFile = "fuzz.yaml";
  auto spec = chimera::load_subsystem_text(text, kFile, chimera::Registry::global());
  if (!spec) {
    // The contract's promise for a bad file: a message that names the file first.
    const std::string& message = spec.error().message;
    CHIMERA_INVARIANT(message.rfind(kFile, 0) == 0, "a loader error names no file");
    return 0;
  }
  const chimera::Resolution resolution = chimera::resolve_subsystem(*spec, chimera::Registry::global());
  const auto violations = chimera::verify_subsystem(resolution);
  (void)chimera::format_violations(violations);
  return 0;
}
