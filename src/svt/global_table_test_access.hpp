#pragma once
// For tests only: a write stopped in the middle, to prove that readers never see it torn and that
// a writer killed or preempted mid-write leaves the last whole value readable. Not installed, not
// exported to any part: only tests/ (which see src/) include it. `write()` is begin_write, then
// store_bytes over every byte, then end_write; bytes not stored between begin_write and end_write
// hold what the slot held before (a write kSlots back). Real-time safe.

#include <cstddef>

#include "chimera/svt/global_table.hpp"

namespace chimera {

class GlobalTableTestAccess {
 public:
  static void begin_write(GlobalTable& table, VarIndex v) noexcept { table.begin_write(v); }
  static void store_bytes(GlobalTable& table, VarIndex v, std::size_t byte_offset, const void* src,
                          std::size_t bytes) noexcept {
    table.store_bytes(v, byte_offset, src, bytes);
  }
  static void end_write(GlobalTable& table, VarIndex v) noexcept { table.end_write(v); }
};

}  // namespace chimera
