#pragma once
// The layout of the global table's shared memory region (private to src/svt).
//
// The region holds offsets only, never pointers: each process maps it at its own address.
//
//   0    Header line 0     magic, layout version, variable count, owner pid, offsets, size
//   64   Header line 1     illegal-configuration flag (written by any task, polled by all)
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
#include <new>
#include <type_traits>

#include "chimera/svt/detail/seq_protocol.hpp"  // kSlots, BlockRef
#include "chimera/svt/elem_type.hpp"

namespace chimera::svt_detail {

inline constexpr std::size_t kCacheLine = 64;
/// "CHIMSVT1" read as a little-endian word: tells a chimera region from anything else in /dev/shm.
inline constexpr std::uint64_t kMagic = 0x315456534d494843ULL;
/// Bumped whenever anything in this file changes shape, so old and new binaries refuse each other.
inline constexpr std::uint32_t kLayoutVersion = 1;
inline constexpr std::size_t kNameCapacity = 64;  // including the terminating NUL

// Atomics in the region must be lock-free: a lock-based atomic_ref would keep its lock in this
// process's memory, invisible to the other processes mapping the region.
static_assert(std::atomic_ref<std::uint64_t>::is_always_lock_free);
static_assert(std::atomic_ref<std::uint64_t>::required_alignment <= alignof(std::uint64_t));

struct Header {
  // Line 0: written once by the creator; `magic` last (release), so whoever sees it sees the rest.
  std::uint64_t magic;
  std::uint32_t layout_version;
  std::uint32_t var_count;
  std::uint64_t owner_pid;  // atomic: a starting process may read it while the owner creates
  std::uint64_t directory_offset;
  std::uint64_t total_size;
  // Line 1: the illegal-configuration flag, the one header word written while running.
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

constexpr std::uint64_t round_up(std::uint64_t n, std::uint64_t to) noexcept { return (n + to - 1) / to * to; }
constexpr std::uint64_t payload_words(std::uint64_t bytes) noexcept { return (bytes + 7) / 8; }
/// One slot: its seq word, then the payload words, padded to whole cache lines.
constexpr std::uint64_t slot_bytes(std::uint64_t words) noexcept { return round_up(8 * (1 + words), kCacheLine); }
/// A variable's block: the version line, then the slots.
constexpr std::uint64_t block_bytes(std::uint64_t words) noexcept { return kCacheLine + kSlots * slot_bytes(words); }
constexpr std::uint64_t directory_offset() noexcept { return sizeof(Header); }

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
