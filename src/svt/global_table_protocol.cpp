// GlobalTable's writes, reads and flag: the protocol of svt/seq_protocol.hpp applied to one
// variable's block, located through the directory once per table (blocks_).

#include <array>
#include <atomic>
#include <cstring>

#include "chimera/svt/global_table.hpp"
#include "svt/seq_protocol.hpp"
#include "svt/shm_layout.hpp"

namespace chimera {

namespace {

namespace d = svt_detail;

/// Stack scratch of read(): 512 B covers every joint-space vector; 8 KiB is the larger tier.
constexpr std::size_t kSmallScratchWords = 64;
constexpr std::size_t kLargeScratchWords = 1024;

/// The reader of the protocol (GlobalTable::read_via). Here, not in read_via, so that read()
/// inlines it: calls between a shared library's exported functions go through the PLT.
inline ReadOutcome read_block(const d::BlockRef& b, void* dst, std::uint64_t seen, std::uint64_t* scratch) noexcept {
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
  // Starved: dst still holds the last complete value this reader got (none if seen is 0).
  return {seen == 0 ? Freshness::kNoData : Freshness::kOld, seen};
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

void GlobalTable::write(VarIndex v, const void* src) noexcept {
  const d::BlockRef& b = blocks_[v];
  const std::uint64_t w = d::next_write(b);
  d::write_begin(b, w);
  d::write_all(b, w, static_cast<const std::byte*>(src));
  d::write_end(b, w);
}

ReadOutcome GlobalTable::read_via(VarIndex v, void* dst, std::uint64_t seen, std::uint64_t* scratch) const noexcept {
  return read_block(blocks_[v], dst, seen, scratch);
}

ReadOutcome GlobalTable::read(VarIndex v, void* dst, std::uint64_t seen) const noexcept {
  const d::BlockRef& b = blocks_[v];
  if (b.words <= kSmallScratchWords) {
    std::array<std::uint64_t, kSmallScratchWords> scratch;  // NOLINT(*-member-init): loaded before use
    return read_block(b, dst, seen, scratch.data());
  }
  if (b.words <= kLargeScratchWords) {
    // Out of line, so that small reads do not reserve 8 KiB of stack.
    auto large = [&]() __attribute__((noinline)) {
      std::array<std::uint64_t, kLargeScratchWords> scratch;  // NOLINT(*-member-init): loaded before use
      return read_block(b, dst, seen, scratch.data());
    };
    return large();
  }
  return read_block(b, dst, seen, nullptr);
}

std::uint64_t GlobalTable::version(VarIndex v) const noexcept {
  // Acquire (in read_version): a caller that sees n may rely on write n being whole in its slot.
  return d::read_version(blocks_[v]);
}

void GlobalTable::set_illegal_configuration(bool raised) noexcept {
  auto* header = d::object_at<d::Header>(base_, 0);
  // Release: what the raising task recorded before raising (its reason, its outputs) is visible
  // to every task that sees the flag through the acquire load below.
  d::Word(header->illegal_configuration).store(raised ? 1 : 0, std::memory_order_release);
}

bool GlobalTable::illegal_configuration() const noexcept {
  auto* header = d::object_at<d::Header>(base_, 0);
  // Acquire: pairs with the release store above.
  return d::Word(header->illegal_configuration).load(std::memory_order_acquire) != 0;
}

}  // namespace chimera
