#pragma once
// How a module's init reaches its ports without seeing the tables behind them: the framework
// hands InitContext a PortAccess (a task's local table), which answers with the storage of one
// port; the typed views of view.hpp are made from that.

#include <cstddef>
#include <string>
#include <string_view>

#include "chimera/svt/elem_type.hpp"
#include "chimera/svt/freshness.hpp"

namespace chimera {

/// One port's storage in a task's local table: `count` elements at `data`, and (inputs) how
/// fresh they are after the last transfer. `data` is null when the port could not be bound.
struct PortWindow {
  void* data = nullptr;
  std::size_t count = 0;
  const Freshness* freshness = nullptr;
};

/// Implemented by the framework's local table. Not real-time safe (init only).
class PortAccess {
 public:
  PortAccess() = default;
  PortAccess(const PortAccess&) = default;
  PortAccess& operator=(const PortAccess&) = default;
  PortAccess(PortAccess&&) = default;
  PortAccess& operator=(PortAccess&&) = default;
  virtual ~PortAccess() = default;

  /// The storage of port `port`, which must be an input (in-var or in-const) if `input`, an output
  /// otherwise, with elements of `type`. On failure the window is empty and `error` says why,
  /// naming the port.
  virtual PortWindow bind(std::string_view port, bool input, ElemType type, std::string& error) = 0;
};

}  // namespace chimera
