#pragma once
// One port of a task bound to a variable of the global table: what resolution produces and what
// a task's local table is made from.

#include <string>

#include "chimera/svt/elem_type.hpp"
#include "chimera/svt/port_kind.hpp"

namespace chimera {

/// One port of a task bound to a variable of the global table (after renaming).
struct PortBinding {
  std::string port;      // the module's port name
  std::string variable;  // the global variable it is bound to
  PortKind kind;
  VarShape shape;
};

}  // namespace chimera
