#pragma once
// For tests only: the global table of a running subsystem, to raise its flag by hand or look at
// its words. Not installed, not exported: only tests/ (which see src/) include it. Any other
// writer of the table would break rule 1 behind verification's back.

#include "chimera/control/subsystem.hpp"
#include "chimera/svt/global_table.hpp"
#include "exec/executive.hpp"

namespace chimera {

class SubsystemTestAccess {
 public:
  /// The table of a subsystem that has not been stopped.
  static GlobalTable& table(Subsystem& subsystem);
  /// The executive of a subsystem that has not been stopped: to post a switch's commit at an
  /// instant of the test's choosing (one already past: a commit posted late).
  static Executive& executive(Subsystem& subsystem);
};

}  // namespace chimera
