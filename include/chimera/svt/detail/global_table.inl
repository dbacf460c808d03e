#pragma once
// Inline bodies of GlobalTable's hot read and write: the protocol of detail/seq_protocol.hpp
// applied to one variable's block (blocks_, located once per table). Inline because they are the
// real-time path's innermost step: through a call into the library a 6-double read cost 7.3 ns,
// more than a mutex-guarded copy (bench/svt_bench.cpp). Variables of up to kRegisterWords whole
// words are read into registers; the rest go out of line (global_table_protocol.cpp).

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>

namespace chimera {

namespace svt_detail {

/// Variables of at most this many whole 8-byte words are read into registers: their words never
/// touch a scratch buffer, whose word stores a wider copy-out could not forward (a 6-double read
/// via scratch 5.0 ns, via registers about 3).
inline constexpr std::size_t kRegisterWords = 8;

/// What a reader that a writer lapped on every attempt reports: its copy is unchanged, so it
/// still holds the last complete value it got (none if seen is 0).
constexpr ReadOutcome starved(std::uint64_t seen) noexcept {
  return {seen == 0 ? Freshness::kNoData : Freshness::kOld, seen};
}

/// The reader of the protocol for a variable of exactly sizeof...(I) whole words, held in
/// registers until read_close says they are whole; only then stored to `dst`.
template <std::size_t... I>
inline ReadOutcome read_words(const BlockRef& ref, void* dst, std::uint64_t seen,
                              std::index_sequence<I...> /*words*/) noexcept {
  // A local copy: dst could alias ref, so its fields would be reloaded after every store through
  // dst; a copy stays in registers.
  const BlockRef b = ref;
  for (int attempt = 0; attempt < kMaxReadAttempts; ++attempt) {
    const std::uint64_t now = read_version(b);
    if (now == 0) return {Freshness::kNoData, 0};
    if (now == seen) return {Freshness::kOld, seen};
    const std::uint64_t s1 = read_open(b, now);
    if (s1 != 2 * now) continue;  // lapped: the slot is already being reused; look at version again
    std::uint64_t* words = b.payload(now % kSlots);
    const std::array<std::uint64_t, sizeof...(I)> got{load_word(&words[I])...};
    if (read_close(b, now, s1)) {
      (std::memcpy(static_cast<std::byte*>(dst) + 8 * I, &got[I], 8), ...);  // dst may be unaligned
      return {Freshness::kNew, now};
    }
  }
  return starved(seen);
}

/// read_words for b's size if it is 1 to kRegisterWords whole words; false otherwise.
inline bool read_in_registers(const BlockRef& b, void* dst, std::uint64_t seen, ReadOutcome& out) noexcept {
  if (b.bytes != 8 * b.words) return false;
  switch (b.words) {
    case 1: out = read_words(b, dst, seen, std::make_index_sequence<1>{}); return true;
    case 2: out = read_words(b, dst, seen, std::make_index_sequence<2>{}); return true;
    case 3: out = read_words(b, dst, seen, std::make_index_sequence<3>{}); return true;
    case 4: out = read_words(b, dst, seen, std::make_index_sequence<4>{}); return true;
    case 5: out = read_words(b, dst, seen, std::make_index_sequence<5>{}); return true;
    case 6: out = read_words(b, dst, seen, std::make_index_sequence<6>{}); return true;
    case 7: out = read_words(b, dst, seen, std::make_index_sequence<7>{}); return true;
    case 8: out = read_words(b, dst, seen, std::make_index_sequence<8>{}); return true;
    default: return false;
  }
}
static_assert(kRegisterWords == 8, "read_in_registers has a case per size");

}  // namespace svt_detail

inline void GlobalTable::write(VarIndex v, const void* src) noexcept {
  const svt_detail::BlockRef& b = blocks_[v];
  const std::uint64_t w = svt_detail::next_write(b);
  svt_detail::write_begin(b, w);
  svt_detail::write_all(b, w, static_cast<const std::byte*>(src));
  svt_detail::write_end(b, w);
}

inline ReadOutcome GlobalTable::read(VarIndex v, void* dst, std::uint64_t seen) const noexcept {
  ReadOutcome out{};
  if (svt_detail::read_in_registers(blocks_[v], dst, seen, out)) return out;
  return read_out_of_line(v, dst, seen, nullptr);
}

inline ReadOutcome GlobalTable::read_via(VarIndex v, void* dst, std::uint64_t seen,
                                         std::uint64_t* scratch) const noexcept {
  ReadOutcome out{};
  if (svt_detail::read_in_registers(blocks_[v], dst, seen, out)) return out;
  return read_out_of_line(v, dst, seen, scratch);
}

inline std::uint64_t GlobalTable::version(VarIndex v) const noexcept {
  // Acquire (in read_version): a caller that sees n may rely on write n being whole in its slot.
  return svt_detail::read_version(blocks_[v]);
}

}  // namespace chimera
