// GlobalTable's split write (for tests), the reads registers cannot hold, and the flag: the protocol of
// detail/seq_protocol.hpp applied to one variable's block (blocks_). The hot read and write are
// inline: detail/global_table.inl.

#include <array>
#include <atomic>
#include <cstring>

#include "chimera/svt/detail/seq_protocol.hpp"
#include "chimera/svt/global_table.hpp"

namespace chimera {

namespace d = svt_detail;

namespace {

/// Stack scratch of read(): 512 B covers every joint-space vector; 8 KiB is the larger tier.
constexpr std::size_t kSmallScratchWords = 64;
constexpr std::size_t kLargeScratchWords = 1024;

/// The reader of the protocol for any size. Loads the words into `scratch` (at least b.words of
/// them) and copies to `dst` only once they are known to be whole; with no scratch it loads
/// straight into `dst`, and then on exhausted retries zeros dst and reports kNoData.
ReadOutcome read_block(const d::BlockRef& b, void* dst, std::uint64_t seen, std::uint64_t* scratch) noexcept {
  for (int attempt = 0; attempt < d::kMaxReadAttempts; ++attempt) {
    const std::uint64_t now = d::read_version(b);
    if (now == 0) return {Freshness::kNoData, 0};
    if (now == seen) return {Freshness::kOld, seen};
    const std::uint64_t s1 = d::read_open(b, now);
    if (s1 != 2 * now) continue;  // lapped: the slot is already being reused; look at version again
    if (scratch != nullptr) {
      d::read_copy(b, now, scratch);
    } else {
      d::read_copy_bytes(b, now, static_cast<std::byte*>(dst));
    }
    if (d::read_close(b, now, s1)) {
      // From local words, so a plain memcpy; dst may be unaligned and shorter than whole words.
      if (scratch != nullptr) std::memcpy(dst, scratch, b.bytes);
      return {Freshness::kNew, now};
    }
  }
  if (scratch == nullptr) {
    // dst may now hold a mix of writes: replace it by a whole value (zeros) and say so.
    std::memset(dst, 0, b.bytes);
    return {Freshness::kNoData, 0};
  }
  return d::starved(seen);
}

}  // namespace

void GlobalTable::begin_write(VarIndex v) noexcept {
  const d::BlockRef& b = blocks_[v];
  d::write_begin(b, d::next_write(b));
}

void GlobalTable::store_bytes(VarIndex v, std::size_t byte_offset, const void* src, std::size_t bytes) noexcept {
  const d::BlockRef& b = blocks_[v];
  d::write_bytes(b, d::next_write(b), byte_offset, static_cast<const std::byte*>(src), bytes);
}

void GlobalTable::end_write(VarIndex v) noexcept {
  const d::BlockRef& b = blocks_[v];
  d::write_end(b, d::next_write(b));
}

ReadOutcome GlobalTable::read_out_of_line(VarIndex v, void* dst, std::uint64_t seen,
                                          std::uint64_t* scratch) const noexcept {
  const d::BlockRef& b = blocks_[v];
  if (scratch != nullptr) return read_block(b, dst, seen, scratch);
  if (b.words <= kSmallScratchWords) {
    std::array<std::uint64_t, kSmallScratchWords> own;  // NOLINT(*-member-init): loaded before use
    return read_block(b, dst, seen, own.data());
  }
  if (b.words <= kLargeScratchWords) {
    // Out of line, so that small reads do not reserve 8 KiB of stack.
    auto large = [&]() __attribute__((noinline)) {
      std::array<std::uint64_t, kLargeScratchWords> own;  // NOLINT(*-member-init): loaded before use
      return read_block(b, dst, seen, own.data());
    };
    return large();
  }
  return read_block(b, dst, seen, nullptr);
}

void GlobalTable::raise_illegal_configuration() noexcept {
  auto* header = d::object_at<d::Header>(base_, 0);
  // Release: what the raiser recorded before raising (its reason, its outputs) is visible to
  // every task that sees the flag up through the acquire load below. An atomic increment, so no
  // interleaving of raisers and lowerers loses a hold.
  d::Word(header->illegal_configuration).fetch_add(1, std::memory_order_release);
}

void GlobalTable::lower_illegal_configuration() noexcept {
  auto* header = d::object_at<d::Header>(base_, 0);
  // Release: as for raising; a task that sees the flag down also sees why it went down.
  const std::uint64_t before = d::Word(header->illegal_configuration).fetch_sub(1, std::memory_order_release);
  CHIMERA_INVARIANT(before != 0, "the illegal-configuration flag lowered more often than raised");
}

bool GlobalTable::illegal_configuration() const noexcept { return illegal_configuration_holds() != 0; }

std::uint64_t GlobalTable::illegal_configuration_holds() const noexcept {
  auto* header = d::object_at<d::Header>(base_, 0);
  // Acquire: pairs with the release increments and decrements above.
  return d::Word(header->illegal_configuration).load(std::memory_order_acquire);
}

}  // namespace chimera
