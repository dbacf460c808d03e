#pragma once
// The state variable protocol (docs/state-variables.md): a sequence counter per slot, kSlots slots
// per variable (the shape is detail/shm_layout.hpp's), one writer per variable (rule 1).
// Installed because GlobalTable's reads and writes are inline (detail/global_table.inl): a call
// into the library cost a 6-double read more than the read itself. Not an API: only src/svt, the
// inline bodies and the protocol's tests use it.
//
// Writer of write w (w = version + 1):
//   seq[w % kSlots] = 2w-1 (relaxed); release fence; payload words (relaxed);
//   seq[w % kSlots] = 2w (release); version = w (release)
// Reader:
//   v = version (acquire); s1 = seq[v % kSlots] (acquire), must be 2v; payload words (relaxed);
//   acquire fence; s2 = seq (relaxed); whole iff s2 == s1. Bounded retries.
// The payload is only ever touched as relaxed atomic words: a plain memcpy of shared bytes that
// races with the writer would be a data race, hence undefined behaviour (Boehm 2012).
//
// The reader is split into steps (open, copy, close) so that a test can run a writer between
// them; read_block (detail/global_table.inl) composes them.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>

#include "chimera/core/invariant.hpp"
#include "chimera/svt/detail/shm_layout.hpp"

// ThreadSanitizer does not model standalone fences, so under it the fences are replaced by
// release stores and acquire loads of the payload words, which TSAN does understand.
#if defined(__SANITIZE_THREAD__)
#define CHIMERA_SVT_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define CHIMERA_SVT_TSAN 1
#endif
#endif

namespace chimera::svt_detail {

using Word = std::atomic_ref<std::uint64_t>;

#ifdef CHIMERA_SVT_TSAN
inline constexpr bool kTsan = true;
#else
inline constexpr bool kTsan = false;
#endif

/// Attempts per read. Each failed attempt means a writer completed at least kSlots - 1 writes
/// while this reader copied once, so eight in a row means the reader is starved; it then keeps
/// its last complete value instead of spinning.
inline constexpr int kMaxReadAttempts = 8;

// ---- payload words ------------------------------------------------------------------------

// NOLINTNEXTLINE(readability-non-const-parameter): atomic_ref needs a non-const object
inline void store_word(std::uint64_t* word, std::uint64_t value) noexcept {
  if constexpr (kTsan) {
    // Release (TSAN only): stands in for begin_write's fence, ordering the odd seq before this word.
    Word(*word).store(value, std::memory_order_release);
  } else {
    // Relaxed: begin_write's release fence orders the odd seq before it, end_write's release
    // store of the even seq orders it before the value is announced.
    Word(*word).store(value, std::memory_order_relaxed);
  }
}

// NOLINTNEXTLINE(readability-non-const-parameter): atomic_ref<const T> does not exist in C++20
inline std::uint64_t load_word(std::uint64_t* word) noexcept {
  if constexpr (kTsan) {
    // Acquire (TSAN only): stands in for the reader's fence, ordering this load before the re-check.
    return Word(*word).load(std::memory_order_acquire);
  } else {
    // Relaxed: the acquire fence in read_close orders it before the re-check of seq.
    return Word(*word).load(std::memory_order_relaxed);
  }
}

// ---- writer -------------------------------------------------------------------------------

/// The number of the write the single writer of `b` is making (or about to begin).
inline std::uint64_t next_write(const BlockRef& b) noexcept {
  // Relaxed: rule 1 makes this thread the only one that stores version, so it reads its own
  // last store; moving a writer to another thread goes through the executive's synchronisation.
  return Word(*b.version).load(std::memory_order_relaxed) + 1;
}

inline void write_begin(const BlockRef& b, std::uint64_t w) noexcept {
  // Relaxed: the release fence below orders it before every payload store; a reader that loads
  // any of those words then sees this odd value (or a later one) in its re-check.
  Word(*b.seq(w % kSlots)).store(2 * w - 1, std::memory_order_relaxed);
  if constexpr (!kTsan) {
    // Release fence: odd seq before the payload; pairs with the reader's acquire fence.
    std::atomic_thread_fence(std::memory_order_release);
  }
}

/// Stores bytes [offset, offset + bytes) of write w. A word only partly covered keeps its other
/// bytes from what the slot held (the caller stores every byte before write_end).
inline void write_bytes(const BlockRef& b, std::uint64_t w, std::size_t offset, const std::byte* src,
                        std::size_t bytes) noexcept {
  CHIMERA_INVARIANT(offset + bytes <= b.bytes, "a store beyond the variable");
  std::uint64_t* words = b.payload(w % kSlots);
  std::size_t pos = offset;
  const std::size_t stop = offset + bytes;
  while (pos < stop) {
    const std::size_t word = pos / 8;
    const std::size_t in_word = pos % 8;
    const std::size_t n = std::min<std::size_t>(8 - in_word, stop - pos);
    std::uint64_t value = 0;
    if (n != 8) {
      // Relaxed: only this thread writes the slot's words, so it reads back its own store.
      value = Word(words[word]).load(std::memory_order_relaxed);
    }
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): bytes of a local word (always allowed)
    std::memcpy(reinterpret_cast<std::byte*>(&value) + in_word, src + (pos - offset), n);
    store_word(&words[word], value);
    pos += n;
  }
}

/// All payload bytes of write w from `src` (any alignment); the tail word's padding is zero.
inline void write_all(const BlockRef& b, std::uint64_t w, const std::byte* src) noexcept {
  std::uint64_t* words = b.payload(w % kSlots);
  const std::size_t full = b.bytes / 8;
  // Unrolled: atomic stores cannot be merged or vectorised, so the loop's own overhead would
  // otherwise cost as much as the stores (36 doubles: 21 ns before, see bench/svt_bench.cpp).
#pragma GCC unroll 4
  for (std::size_t i = 0; i < full; ++i) {
    std::uint64_t value = 0;
    std::memcpy(&value, src + 8 * i, 8);
    store_word(&words[i], value);
  }
  if (const std::size_t tail = b.bytes % 8; tail != 0) {
    std::uint64_t value = 0;
    std::memcpy(&value, src + 8 * full, tail);
    store_word(&words[full], value);
  }
}

inline void write_end(const BlockRef& b, std::uint64_t w) noexcept {
  // Release: the payload stores happen-before any read whose acquire load of seq sees 2w.
  Word(*b.seq(w % kSlots)).store(2 * w, std::memory_order_release);
  // Release: a reader whose acquire load of version sees w then sees seq = 2w in the slot.
  Word(*b.version).store(w, std::memory_order_release);
}

// ---- reader -------------------------------------------------------------------------------

/// The newest complete write (0: none yet).
inline std::uint64_t read_version(const BlockRef& b) noexcept {
  // Acquire: pairs with write_end's release store of version, so seq = 2v of that write is
  // visible to read_open; s1 then differs from 2v only if a writer has lapped the reader.
  return Word(*b.version).load(std::memory_order_acquire);
}

/// Opens write v's slot: returns its seq, which is 2v unless a writer is reusing the slot.
inline std::uint64_t read_open(const BlockRef& b, std::uint64_t v) noexcept {
  // Acquire: pairs with write_end's release store of 2v, so write v's payload is visible to the
  // loads of read_copy.
  return Word(*b.seq(v % kSlots)).load(std::memory_order_acquire);
}

/// Loads the slot's words into local words `out` (b.words of them).
inline void read_copy(const BlockRef& b, std::uint64_t v, std::uint64_t* out) noexcept {
  std::uint64_t* words = b.payload(v % kSlots);
#pragma GCC unroll 4  // as in write_all
  for (std::size_t i = 0; i < b.words; ++i) out[i] = load_word(&words[i]);
}

/// Loads the slot's words straight into `dst` (any alignment, b.bytes long).
inline void read_copy_bytes(const BlockRef& b, std::uint64_t v, std::byte* dst) noexcept {
  std::uint64_t* words = b.payload(v % kSlots);
  for (std::size_t i = 0; i < b.words; ++i) {
    const std::uint64_t value = load_word(&words[i]);
    std::memcpy(dst + 8 * i, &value, std::min<std::size_t>(8, b.bytes - 8 * i));
  }
}

/// True if what read_copy loaded is whole: no writer touched the slot since read_open saw s1.
inline bool read_close(const BlockRef& b, std::uint64_t v, std::uint64_t s1) noexcept {
  if constexpr (!kTsan) {
    // Acquire fence: if any payload load saw a later write's store, that writer's release fence
    // synchronises with this one and the re-check below sees its odd seq.
    std::atomic_thread_fence(std::memory_order_acquire);
  }
  // Relaxed: ordered after the payload loads by the acquire fence (the acquire loads under TSAN).
  return Word(*b.seq(v % kSlots)).load(std::memory_order_relaxed) == s1;
}

}  // namespace chimera::svt_detail
