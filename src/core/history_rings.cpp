#include "chimera/core/history_rings.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "chimera/core/invariant.hpp"

namespace chimera {

namespace {

using Word = std::atomic_ref<std::uint64_t>;

constexpr std::size_t kHeaderWords = 2;  // a record's stamp and time words, before its payload

// A shared block of no rings still maps one word: a mapping, and a reservation, of nothing fails.
std::size_t mapped_bytes(std::size_t bytes) { return std::max(bytes, sizeof(std::uint64_t)); }

Error system_error(const char* what, const char* call) {
  return make_error(Errc::kSystem, std::string("the flight recorder's ") + what + ": " + call +
                                       " failed: " + std::generic_category().message(errno));
}

}  // namespace

std::size_t HistoryRings::add(std::uint32_t capacity, std::uint32_t payload_bytes) {
  CHIMERA_INVARIANT(block_ == nullptr, "a ring added after the block was allocated");
  CHIMERA_INVARIANT(capacity >= 1, "a ring of no records");
  Ring ring;
  ring.offset = words_;
  ring.capacity = capacity;
  ring.payload_bytes = payload_bytes;
  ring.payload_words = (payload_bytes + 7) / 8;
  words_ += 1 + static_cast<std::size_t>(capacity) * (kHeaderWords + ring.payload_words);
  rings_.push_back(ring);
  return rings_.size() - 1;
}

HistoryRings::~HistoryRings() {
  if (fd_ >= 0) {
    if (block_ != nullptr) ::munmap(block_, mapped_bytes(bytes()));
    ::close(fd_);
  }
}

void HistoryRings::allocate() {
  CHIMERA_INVARIANT(block_ == nullptr, "the block allocated twice");
  // NOLINTNEXTLINE(cppcoreguidelines-avoid-c-arrays): one block of a size known only now, never resized
  private_ = std::make_unique<std::uint64_t[]>(words_);  // value-initialised: every word 0
  block_ = private_.get();
}

Result<void> HistoryRings::map_shared(const char* what) {
  void* p = ::mmap(nullptr, mapped_bytes(bytes()), PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
  if (p == MAP_FAILED) return system_error(what, "mmap");
  block_ = static_cast<std::uint64_t*>(p);
  return {};
}

Result<void> HistoryRings::allocate_shared() {
  CHIMERA_INVARIANT(block_ == nullptr && fd_ < 0, "the block allocated twice");
  fd_ = ::memfd_create("chimera-history", MFD_CLOEXEC);  // no name in /dev/shm: nothing left behind
  if (fd_ < 0) return system_error("block", "memfd_create");
  // A new memfd reads as zeros: every ring empty. Reserved whole, as the global table is.
  if (const int rc = ::posix_fallocate(fd_, 0, static_cast<off_t>(mapped_bytes(bytes()))); rc != 0) {
    errno = rc;  // it returns the error rather than setting errno
    return system_error("block", "posix_fallocate");
  }
  return map_shared("block");
}

Result<void> HistoryRings::attach(int fd) {
  CHIMERA_INVARIANT(block_ == nullptr && fd_ < 0, "the block allocated twice");
  fd_ = fd;
  struct stat st {};
  if (::fstat(fd_, &st) != 0) return system_error("shared block", "fstat");
  if (static_cast<std::size_t>(st.st_size) != mapped_bytes(bytes()))
    return make_error(Errc::kInvalidInput, "the flight recorder's shared block is " + std::to_string(st.st_size) +
                                               " bytes, where its rings here take " +
                                               std::to_string(mapped_bytes(bytes())) +
                                               ": the main process laid them out differently");
  return map_shared("shared block");
}

void HistoryRings::write(std::size_t r, std::int64_t time_ns, const void* payload) noexcept {
  const Ring& ring = rings_[r];
  std::uint64_t* head = block_ + ring.offset;
  // Relaxed: this thread is the ring's only writer, so it reads back its own last store (or that of
  // the writer before it, in this process or another, which a switch's commit ordered before it).
  const std::uint64_t w = Word(*head).load(std::memory_order_relaxed) + 1;
  std::uint64_t* record = head + 1 + ((w - 1) % ring.capacity) * (kHeaderWords + ring.payload_words);
  // Relaxed: the release stores of the words below order it before them (see the header).
  Word(record[0]).store(2 * w - 1, std::memory_order_relaxed);
  // Release: a reader that loads this word also sees the odd stamp above in its re-check.
  Word(record[1]).store(static_cast<std::uint64_t>(time_ns), std::memory_order_release);
  const auto* bytes = static_cast<const std::byte*>(payload);
  for (std::uint32_t i = 0; i < ring.payload_words; ++i) {
    std::uint64_t value = 0;
    const std::size_t n = std::min<std::size_t>(8, ring.payload_bytes - std::size_t{i} * 8);
    std::memcpy(&value, bytes + std::size_t{i} * 8, n);
    // Release: as the time word.
    Word(record[kHeaderWords + i]).store(value, std::memory_order_release);
  }
  // Release: the record's words before the even stamp that says it is whole.
  Word(record[0]).store(2 * w, std::memory_order_release);
  // Release: the whole record before the count that announces it.
  Word(*head).store(w, std::memory_order_release);
}

std::uint64_t HistoryRings::written(std::size_t r) const noexcept {
  // Acquire: pairs with the writer's release store of the head.
  return Word(block_[rings_[r].offset]).load(std::memory_order_acquire);
}

HistoryRings::Records HistoryRings::read(std::size_t r) const {
  const Ring& ring = rings_[r];
  std::uint64_t* head = block_ + ring.offset;
  const std::uint64_t last = written(r);
  const std::uint64_t first = last > ring.capacity ? last - ring.capacity + 1 : 1;
  Records out(ring.payload_words);
  out.reserve(static_cast<std::size_t>(last - first + 1));
  for (std::uint64_t w = first; w <= last; ++w) {
    std::uint64_t* record = head + 1 + ((w - 1) % ring.capacity) * (kHeaderWords + ring.payload_words);
    // Acquire: pairs with the writer's release store of the even stamp: the words are its.
    const std::uint64_t s1 = Word(record[0]).load(std::memory_order_acquire);
    if (s1 != 2 * w) continue;  // already being overwritten by a later record
    // Acquire (each word): orders the loads before the re-check of the stamp below.
    const std::span<std::uint64_t> words =
        out.append(static_cast<std::int64_t>(Word(record[1]).load(std::memory_order_acquire)));
    for (std::uint32_t i = 0; i < ring.payload_words; ++i)
      words[i] = Word(record[kHeaderWords + i]).load(std::memory_order_acquire);
    // Relaxed: the acquire loads above keep it after them.
    if (Word(record[0]).load(std::memory_order_relaxed) != s1) out.drop_last();  // overwritten while copied
  }
  return out;
}

}  // namespace chimera
