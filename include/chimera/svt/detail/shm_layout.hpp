#pragma once
// The shape of the global table's shared memory region: the one definition of it. Everything a
// process that maps the region must agree on is here, and kLayoutVersion is a fingerprint of all
// of it (sizes, offsets, constants), so that it changes with any of it; attach() refuses a region
// of another version. Installed (as detail) because GlobalTable's inline read and write use
// BlockRef and kSlots; not an API.
//
// The region holds offsets only, never pointers: each process maps it at its own address.
//
//   0    Header line 0     magic, layout version, variable count, owner pid, offsets, size
//   64   Header line 1     illegal-configuration flag: a count of its raisers (written by any
//                          task and by the subsystem interface, polled by all)
//   128  Directory         VarCount DirEntry records: name, type, count, words, block offset
//   ...  Block of var 0    (64-aligned) version line, then kSlots slots of [seq | payload words]
//   ...  Block of var 1    ...
//
// Every word that threads write independently of each other sits on its own cache line: the
// flag, each variable's version, and each slot (a slot's seq and payload have a single writer
// and are written together, so they share lines).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <new>
#include <type_traits>

#include "chimera/svt/elem_type.hpp"

namespace chimera::svt_detail {

/// Slots per variable. Two would do for a writer preempted mid-write (the latch idea); four give
/// a reader three whole writes of grace before a fast writer can reuse the slot it is copying.
inline constexpr std::uint64_t kSlots = 4;
inline constexpr std::size_t kCacheLine = 64;
/// "CHIMSVT1" read as a little-endian word: tells a chimera region from anything else in /dev/shm.
inline constexpr std::uint64_t kMagic = 0x315456534d494843ULL;
inline constexpr std::size_t kNameCapacity = 64;  // including the terminating NUL
/// Bumped by hand when the meaning of a word changes without its size or place (the flag became
/// a count of raisers in revision 2; in 3 the creator holds an flock on the region while it
/// lives, and the owner pid is for messages only); every size, offset and constant is in the
/// fingerprint anyway.
inline constexpr std::uint64_t kLayoutRevision = 3;

// Atomics in the region must be lock-free: a lock-based atomic_ref would keep its lock in this
// process's memory, invisible to the other processes mapping the region.
static_assert(std::atomic_ref<std::uint64_t>::is_always_lock_free);
static_assert(std::atomic_ref<std::uint64_t>::required_alignment <= alignof(std::uint64_t));

struct Header {
  // Line 0: written once by the creator; `magic` last (release), so whoever sees it sees the rest.
  std::uint64_t magic;
  std::uint32_t layout_version;
  std::uint32_t var_count;
  std::uint64_t owner_pid;  // the creator's, for messages; liveness is its flock (region_ownership.hpp)
  std::uint64_t directory_offset;
  std::uint64_t total_size;
  std::uint64_t layout_fingerprint;  // kLayoutFingerprint of the creator
  // Line 1: the illegal-configuration flag, the one header word written while running: how many
  // reasons hold it up now (tasks in ERROR, a switch under way, ...); raised while non-zero.
  alignas(kCacheLine) std::uint64_t illegal_configuration;
};
static_assert(std::is_standard_layout_v<Header> && std::is_trivially_copyable_v<Header>);
static_assert(offsetof(Header, illegal_configuration) == kCacheLine);
static_assert(sizeof(Header) == 2 * kCacheLine);

struct DirEntry {
  std::array<char, kNameCapacity> name;  // NUL-terminated
  std::uint32_t count;
  std::uint8_t elem_type;  // ElemType
  std::array<std::uint8_t, 3> reserved;
  std::uint32_t payload_words;  // ceil(bytes / 8)
  std::uint32_t reserved2;
  std::uint64_t block_offset;  // from the start of the region, 64-aligned
};
static_assert(std::is_standard_layout_v<DirEntry> && std::is_trivially_copyable_v<DirEntry>);
static_assert(sizeof(DirEntry) == 88);

/// The words of one variable's block, located once per table in this process's mapping.
struct BlockRef {
  std::uint64_t* version;  // its own cache line
  std::byte* slots;        // slot k starts at slots + k * slot_stride
  std::uint64_t slot_stride;
  std::uint32_t words;
  std::uint32_t bytes;  // payload bytes actually used (<= 8 * words)

  [[nodiscard]] std::uint64_t* seq(std::uint64_t slot) const noexcept {
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): a slot starts with its seq word
    return std::launder(reinterpret_cast<std::uint64_t*>(slots + slot * slot_stride));
  }
  [[nodiscard]] std::uint64_t* payload(std::uint64_t slot) const noexcept { return seq(slot) + 1; }
};

constexpr std::uint64_t round_up(std::uint64_t n, std::uint64_t to) noexcept { return (n + to - 1) / to * to; }
constexpr std::uint64_t payload_words(std::uint64_t bytes) noexcept { return (bytes + 7) / 8; }
/// One slot: its seq word, then the payload words, padded to whole cache lines.
constexpr std::uint64_t slot_bytes(std::uint64_t words) noexcept { return round_up(8 * (1 + words), kCacheLine); }
/// A variable's block: the version line, then the slots.
constexpr std::uint64_t block_bytes(std::uint64_t words) noexcept { return kCacheLine + kSlots * slot_bytes(words); }
constexpr std::uint64_t directory_offset() noexcept { return sizeof(Header); }

/// FNV-1a over 64-bit words, at compile time.
constexpr std::uint64_t fingerprint(std::initializer_list<std::uint64_t> words) noexcept {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const std::uint64_t w : words) {
    for (int byte = 0; byte < 8; ++byte) {
      h ^= (w >> (8 * byte)) & 0xffU;
      h *= 0x100000001b3ULL;
    }
  }
  return h;
}

/// Everything the shape depends on, as one number: the revision, the constants, and the size and
/// offset of every field of the header and the directory, and the block formula at two sizes.
/// Written into the header by create() and compared by attach().
inline constexpr std::uint64_t kLayoutFingerprint = fingerprint({
    kLayoutRevision,
    kSlots,
    kCacheLine,
    kMagic,
    kNameCapacity,
    sizeof(Header),
    offsetof(Header, magic),
    offsetof(Header, layout_version),
    offsetof(Header, var_count),
    offsetof(Header, owner_pid),
    offsetof(Header, directory_offset),
    offsetof(Header, total_size),
    offsetof(Header, layout_fingerprint),
    offsetof(Header, illegal_configuration),
    sizeof(DirEntry),
    offsetof(DirEntry, name),
    offsetof(DirEntry, count),
    offsetof(DirEntry, elem_type),
    offsetof(DirEntry, payload_words),
    offsetof(DirEntry, block_offset),
    block_bytes(1),
    block_bytes(9),
    directory_offset(),
});
/// The header's 32-bit version field: the fingerprint folded, so that even a binary that reads
/// only the old field sees a different number.
inline constexpr std::uint32_t kLayoutVersion =
    static_cast<std::uint32_t>(kLayoutFingerprint ^ (kLayoutFingerprint >> 32U));

/// An object of the region at `offset`. The creator constructs every object with placement new;
/// a process that attaches sees the same bytes, hence the launder.
template <class T>
T* object_at(std::byte* base, std::uint64_t offset) noexcept {
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): the region is bytes, addressed by offset
  return std::launder(reinterpret_cast<T*>(base + offset));
}

inline const DirEntry* dir_entry(std::byte* base, std::uint32_t v) noexcept {
  const auto* header = object_at<Header>(base, 0);
  return object_at<DirEntry>(base, header->directory_offset + std::uint64_t{v} * sizeof(DirEntry));
}

inline BlockRef block_ref(std::byte* base, std::uint32_t v) noexcept {
  const DirEntry* e = dir_entry(base, v);
  std::byte* block = base + e->block_offset;
  return BlockRef{object_at<std::uint64_t>(block, 0), block + kCacheLine, slot_bytes(e->payload_words),
                  e->payload_words,
                  static_cast<std::uint32_t>(elem_size(static_cast<ElemType>(e->elem_type)) * e->count)};
}

}  // namespace chimera::svt_detail
