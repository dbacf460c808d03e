#pragma once
// The two shapes of a Reply that the command API's files make (private to the control part).

#include <string>
#include <utility>

#include "chimera/control/control.hpp"

namespace chimera::control_detail {

/// A refused command: one line saying why; nothing changed.
inline Reply refused(std::string message) {
  Reply r;
  r.ok = false;
  r.text = std::move(message) + "\n";
  return r;
}

/// A command carried out, with what it prints.
inline Reply said(std::string text) {
  Reply r;
  r.text = std::move(text);
  return r;
}

}  // namespace chimera::control_detail
