#pragma once
#include <cstdint>
#include <string_view>

namespace chimera {

/// The four kinds of port of a port-based object (paper 3.3). They differ in when the framework
/// transfers them: in-consts once before init (and reinit), in-vars before every method,
/// out-vars after every method, out-consts after init.
enum class PortKind : std::uint8_t { kInConst, kInVar, kOutConst, kOutVar };

constexpr bool is_input(PortKind k) noexcept { return k == PortKind::kInConst || k == PortKind::kInVar; }
constexpr bool is_const(PortKind k) noexcept { return k == PortKind::kInConst || k == PortKind::kOutConst; }

constexpr std::string_view port_kind_name(PortKind k) noexcept {
  switch (k) {
    case PortKind::kInConst: return "in-const";
    case PortKind::kInVar: return "in-var";
    case PortKind::kOutConst: return "out-const";
    case PortKind::kOutVar: return "out-var";
  }
  return "?";
}

}  // namespace chimera
