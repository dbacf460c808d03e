#pragma once
// A task's local state variable table (paper 3.1): private copies of only the variables the task
// uses, and the transfers between them and the global table.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/core/history_rings.hpp"
#include "chimera/core/result.hpp"
#include "chimera/svt/elem_type.hpp"
#include "chimera/svt/freshness.hpp"
#include "chimera/svt/global_table.hpp"
#include "chimera/svt/port_access.hpp"
#include "chimera/svt/port_binding.hpp"
#include "chimera/svt/port_kind.hpp"
#include "chimera/svt/view.hpp"

namespace chimera {

class LocalTable final : public PortAccess {
 public:
  /// Allocates local storage for `ports` and resolves each variable in `global` once.
  /// Not real-time safe.
  static Result<LocalTable> create(GlobalTable& global, std::span<const PortBinding> ports);

  /// A typed view onto port `port`; fails if the port does not exist, has another kind
  /// (input vs output), or T is not its element type. Used in init. Not real-time safe.
  template <class T>
  Result<In<T>> input(std::string_view port);
  template <class T>
  Result<Out<T>> output(std::string_view port);
  /// PortAccess, for InitContext: the same lookups, untyped. Not real-time safe.
  PortWindow bind(std::string_view port, bool input, ElemType type, std::string& error) override;

  // Transfers (real-time safe): global -> local for inputs, local -> global for outputs.
  void pull_in_consts() noexcept;
  void pull_in_vars() noexcept;
  /// Publishes the outputs' local copies; with a history kept, each is also recorded, stamped
  /// `at_ns` (the time of the release whose cycle produced it, on the subsystem's clock).
  void push_out_vars(std::int64_t at_ns) noexcept;
  void push_out_consts() noexcept;

  /// Zeros the local copies of inputs and marks them kNoData, so that a task joining a
  /// configuration reads everything anew. Outputs are the module's and keep their values.
  /// Real-time safe.
  void reset_inputs() noexcept;

  /// The flight recorder (docs/flight-recorder.md): from now on each push_out_vars also writes
  /// output variable v's value to ring `ring_of_var[v]` of `rings` (-1: not recorded); nullptr
  /// stops it. The rings outlive the table. Not real-time safe.
  void keep_history(HistoryRings* rings, std::span<const std::int32_t> ring_of_var) noexcept;

  [[nodiscard]] std::span<const PortBinding> ports() const noexcept { return ports_; }

 private:
  struct Slot {
    VarIndex var;
    PortKind kind;
    std::uint32_t offset;  // into storage_
    std::uint32_t bytes;
    std::uint64_t seen;  // version of the global value held locally
    std::int32_t ring;   // its flight recorder ring, -1: none
  };
  LocalTable() = default;
  Result<const Slot*> find_slot(std::string_view port, bool want_input, ElemType type) const;

  void pull(PortKind kind) noexcept;
  void push(PortKind kind) noexcept;

  GlobalTable* global_ = nullptr;
  HistoryRings* history_ = nullptr;  // the flight recorder's, or none
  std::vector<PortBinding> ports_;
  std::vector<Slot> slots_;                            // parallel to ports_
  std::vector<Freshness> freshness_;                   // parallel to ports_
  std::vector<std::max_align_t> storage_;              // aligned for any element type
  std::array<std::vector<std::uint32_t>, 4> by_kind_;  // indices into slots_, per PortKind: no test per cycle
  std::vector<std::uint64_t> scratch_;                 // read buffer as large as the largest input: a read that
                                                       // a writer laps leaves the local copy whole
};

}  // namespace chimera

#include "chimera/svt/detail/local_table.inl"
