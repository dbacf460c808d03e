#include "chimera/core/history_rings.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>

#include "chimera/core/invariant.hpp"

namespace chimera {

namespace {

using Word = std::atomic_ref<std::uint64_t>;

constexpr std::size_t kHeaderWords = 2;  // a record's stamp and time words, before its payload

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

void HistoryRings::allocate() {
  CHIMERA_INVARIANT(block_ == nullptr, "the block allocated twice");
  // NOLINTNEXTLINE(cppcoreguidelines-avoid-c-arrays): one block of a size known only now, never resized
  block_ = std::make_unique<std::uint64_t[]>(words_);  // value-initialised: every word 0
}

void HistoryRings::write(std::size_t r, std::int64_t time_ns, const void* payload) noexcept {
  const Ring& ring = rings_[r];
  std::uint64_t* head = block_.get() + ring.offset;
  // Relaxed: this thread is the ring's only writer, so it reads back its own last store.
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

std::vector<HistoryRings::Record> HistoryRings::read(std::size_t r) const {
  const Ring& ring = rings_[r];
  std::uint64_t* head = block_.get() + ring.offset;
  const std::uint64_t last = written(r);
  const std::uint64_t first = last > ring.capacity ? last - ring.capacity + 1 : 1;
  std::vector<Record> out;
  out.reserve(static_cast<std::size_t>(last - first + 1));
  for (std::uint64_t w = first; w <= last; ++w) {
    std::uint64_t* record = head + 1 + ((w - 1) % ring.capacity) * (kHeaderWords + ring.payload_words);
    // Acquire: pairs with the writer's release store of the even stamp: the words are its.
    const std::uint64_t s1 = Word(record[0]).load(std::memory_order_acquire);
    if (s1 != 2 * w) continue;  // already being overwritten by a later record
    Record copy;
    // Acquire (each word): orders the loads before the re-check of the stamp below.
    copy.time_ns = static_cast<std::int64_t>(Word(record[1]).load(std::memory_order_acquire));
    copy.words.resize(ring.payload_words);
    for (std::uint32_t i = 0; i < ring.payload_words; ++i)
      copy.words[i] = Word(record[kHeaderWords + i]).load(std::memory_order_acquire);
    // Relaxed: the acquire loads above keep it after them.
    if (Word(record[0]).load(std::memory_order_relaxed) != s1) continue;  // overwritten while copied
    out.push_back(std::move(copy));
  }
  return out;
}

}  // namespace chimera
