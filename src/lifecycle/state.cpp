#include "chimera/lifecycle/state.hpp"

namespace chimera {

std::optional<Signal> parse_signal(std::string_view name) noexcept {
  for (Signal s : {Signal::kSpawn, Signal::kOn, Signal::kOff, Signal::kKill, Signal::kClear})
    if (signal_name(s) == name) return s;
  return std::nullopt;
}

}  // namespace chimera
