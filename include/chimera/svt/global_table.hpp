#pragma once
// The global state variable table (paper 3.1, Figure 5): one region of POSIX shared memory,
// laid out with offsets only, holding the most recent value of every variable of the subsystem.
// Protocol (docs/state-variables.md): one writer per variable, several slots per variable, a
// sequence number per slot; readers never see a torn value and never wait for a writer, even
// one preempted mid-write.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "chimera/core/result.hpp"
#include "chimera/svt/detail/seq_protocol.hpp"
#include "chimera/svt/elem_type.hpp"
#include "chimera/svt/freshness.hpp"

namespace chimera {

/// Index of a variable in the global table; resolved once, used on the real-time path.
using VarIndex = std::uint32_t;

/// What a read brought back.
struct ReadOutcome {
  Freshness freshness;    // kNoData: never written; kOld: nothing newer than `seen`; kNew: copied
  std::uint64_t version;  // version now held by the reader's copy (pass it back as `seen`)
};

class GlobalTable {
 public:
  /// Where the variables' blocks go: packed one after the other (each on its own cache lines),
  /// or each on pages of its own, after a header page and the directory's pages, so that a
  /// process can be let write only its own variables (restrict_writes(): module processes).
  enum class Placement : std::uint8_t { kPacked, kPagePerVariable };

  /// Creates the region /chimera_<name> (mode 0600) and lays out `vars`, its memory reserved up
  /// front: a full /dev/shm is an error saying so, never a SIGBUS later. The returned owner
  /// holds a lock on the region while it lives and unlinks it when destroyed. A region of the
  /// same name whose lock nobody holds is stale (its creator is gone, however it ended and
  /// whatever became of its pid) and is replaced; one whose owner lives is refused. Not
  /// real-time safe.
  static Result<GlobalTable> create(std::string_view subsystem_name, std::span<const VarSpec> vars,
                                    Placement placement = Placement::kPacked);
  /// Removes the name of every region this process created and still owns, each only if the name
  /// is still that region's: for a signal handler about to end the process the abrupt way, so
  /// that no region is left behind. The mappings stay valid. Async-signal-safe.
  static void remove_owned_names_now() noexcept;
  /// Removes every stale region (its owner gone, however it ended) whose subsystem name starts
  /// with `name_prefix`, e.g. the measuring runs of a killed `chimera analyze`, whose names carry
  /// their pid and so are never created again. Live ones are left. Returns how many it removed.
  /// Not real-time safe.
  static std::size_t reclaim_stale(std::string_view name_prefix);
  /// Maps an existing region read-write, e.g. from another process. A region of another layout
  /// (detail/shm_layout.hpp's fingerprint differs: another version of Chimera made it) is refused
  /// with a message saying so. Not real-time safe.
  static Result<GlobalTable> attach(std::string_view subsystem_name);

  GlobalTable(GlobalTable&& other) noexcept;
  GlobalTable& operator=(GlobalTable&& other) noexcept;
  GlobalTable(const GlobalTable&) = delete;
  GlobalTable& operator=(const GlobalTable&) = delete;
  ~GlobalTable();

  /// Makes this process's mapping read-only but for the header page (the illegal-configuration
  /// flag, which any task may raise) and the blocks of `writable`: a write anywhere else, a stray
  /// pointer's, faults in this process instead of changing another writer's variable or the
  /// directory. Refused for a region not laid out kPagePerVariable. Not real-time safe.
  [[nodiscard]] Result<void> restrict_writes(std::span<const VarIndex> writable);

  /// Name of the shared memory object, e.g. "/chimera_fig4".
  [[nodiscard]] const std::string& shm_name() const { return shm_name_; }
  [[nodiscard]] std::size_t size() const noexcept;
  [[nodiscard]] std::optional<VarIndex> find(std::string_view name) const;
  [[nodiscard]] std::string_view name(VarIndex v) const noexcept;
  [[nodiscard]] VarShape shape(VarIndex v) const noexcept;

  /// Publishes shape(v).bytes() bytes from `src` as the newest value. Only one thread may write a
  /// given variable (rule 1). Real-time safe, wait-free. Inline, as read() is.
  void write(VarIndex v, const void* src) noexcept;
  /// Copies the newest complete value into `dst` if it is newer than `seen` (a version returned
  /// by an earlier read, 0 at first). Never torn, never waits for a writer; if a writer laps the
  /// reader on every bounded retry, reports kOld (kNoData if `seen` is 0) and leaves `dst` as it
  /// was. Variables over 8 KiB have no stack scratch here: on exhausted retries `dst` is zeroed
  /// and kNoData reported (LocalTable has scratch and keeps the old copy). Real-time safe.
  /// Inline (detail/global_table.inl): through a call into the library a 6-double read took 7.3 ns,
  /// more than a mutex-guarded copy.
  ReadOutcome read(VarIndex v, void* dst, std::uint64_t seen) const noexcept;
  /// Completed writes of v so far (0: never written). Real-time safe.
  [[nodiscard]] std::uint64_t version(VarIndex v) const noexcept;

  /// The global illegal-configuration flag (paper 3.4): raised while anything holds it. Real-time
  /// safe, any process.
  [[nodiscard]] bool illegal_configuration() const noexcept;
  /// How many holds keep the flag raised now (tasks in ERROR, a switch under way, ...).
  [[nodiscard]] std::uint64_t illegal_configuration_holds() const noexcept;
  /// One hold more, and one fewer: whoever raises lowers exactly once, so the flag is lowered only
  /// when the last reason for it has gone, whatever the interleaving (it is a count, changed by
  /// atomic increments, never a stored true or false). Lowering with no hold is a broken
  /// invariant. Real-time safe, any thread or process.
  void raise_illegal_configuration() noexcept;
  void lower_illegal_configuration() noexcept;

 private:
  friend class LocalTable;             // reads through its own scratch buffer (read_via)
  friend class GlobalTableTestAccess;  // tests: a write stopped half way (src/svt/global_table_test_access.hpp)

  GlobalTable() = default;
  void release() noexcept;
  void locate_blocks();
  // The write split in three (for GlobalTableTestAccess): begin, some bytes, end.
  void begin_write(VarIndex v) noexcept;
  void store_bytes(VarIndex v, std::size_t byte_offset, const void* src, std::size_t bytes) noexcept;
  void end_write(VarIndex v) noexcept;
  // The reads that registers cannot hold (over 8 words, or not whole words): through `scratch`, or
  // with none given, through stack scratch of read()'s own.
  ReadOutcome read_out_of_line(VarIndex v, void* dst, std::uint64_t seen, std::uint64_t* scratch) const noexcept;
  // The reader of the protocol. Loads the words into `scratch` (at least as many words as the
  // payload) and copies to `dst` only once they are known to be whole; with no scratch it loads
  // straight into `dst`, and then on exhausted retries zeros dst and reports kNoData.
  ReadOutcome read_via(VarIndex v, void* dst, std::uint64_t seen, std::uint64_t* scratch) const noexcept;

  std::string shm_name_;
  std::byte* base_ = nullptr;  // start of the mapping; everything inside is found by offset
  // Each variable's block in this process's mapping, located once through the directory when the
  // table is created or attached, so that reads and writes skip the directory. Process-local
  // pointers; the region itself holds only offsets.
  std::vector<svt_detail::BlockRef> blocks_;
  std::size_t mapped_bytes_ = 0;
  bool owner_ = false;
  int lock_fd_ = -1;     // the creator's: the region's file, holding the owner's lock while open
  int owned_note_ = -1;  // the creator's slot for remove_owned_names_now()
};

/// Holds the illegal-configuration flag of `table` raised while it lives: one raise, one lower.
/// Real-time safe.
class IllegalConfigurationHold {
 public:
  explicit IllegalConfigurationHold(GlobalTable& table) noexcept : table_(&table) {
    table_->raise_illegal_configuration();
  }
  ~IllegalConfigurationHold() {
    if (table_ != nullptr) table_->lower_illegal_configuration();
  }
  IllegalConfigurationHold(IllegalConfigurationHold&& other) noexcept : table_(std::exchange(other.table_, nullptr)) {}
  IllegalConfigurationHold& operator=(IllegalConfigurationHold&&) = delete;
  IllegalConfigurationHold(const IllegalConfigurationHold&) = delete;
  IllegalConfigurationHold& operator=(const IllegalConfigurationHold&) = delete;

 private:
  GlobalTable* table_;
};

}  // namespace chimera

#include "chimera/svt/detail/global_table.inl"
