#pragma once
// Rings of the most recent records, many in one block of memory allocated once: the flight
// recorder's storage (docs/flight-recorder.md). Each ring has one writer at a time, which
// overwrites its oldest record and never waits; any thread may copy a ring out meanwhile and gets
// only whole records (a record being overwritten as it is copied is left out, never torn).
//
// Protocol, per record (a sequence word, a time word, then the payload's words), for write w of a
// ring (w = 1, 2, ...; its slot is (w - 1) % capacity):
//   stamp = 2w-1 (relaxed); time and payload words (release); stamp = 2w (release); head = w (release)
// Reader, for each w from head - capacity + 1 to head:
//   s1 = stamp (acquire), must be 2w; words (acquire); s2 = stamp (relaxed); whole iff s2 == s1.
// A word loaded by acquire that a later writer stored carries that writer's odd stamp with it, so
// the re-check sees it: the same argument as the state variable table's (docs/state-variables.md),
// with release/acquire on each word instead of fences, which costs nothing on x86 and which
// ThreadSanitizer understands.
//
// The block is private memory, or a memfd shared with module processes (docs/processes.md): the
// main process creates it, a worker that declared the same rings attaches to it, and both write
// and read the same records. Nothing in it is a pointer: a ring is found at an offset.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "chimera/core/result.hpp"

namespace chimera {

class HistoryRings {
 public:
  /// A ring's place in the block: offsets into it, never pointers.
  struct Ring {
    std::size_t offset = 0;      // of its head word; its records follow
    std::uint32_t capacity = 0;  // records
    std::uint32_t payload_words = 0;
    std::uint32_t payload_bytes = 0;
  };
  /// One record as copied out: its time and its payload's words (a view into its Records).
  struct Record {
    std::int64_t time_ns = 0;
    std::span<const std::uint64_t> words;
  };
  /// The records of one ring as copied out, oldest first. Their times are one array and their
  /// words another: a copy of ten thousand records is two allocations, which a process with
  /// locked memory gives back when they are freed, where one allocation per record stayed in
  /// its heap for good (a run's first dump grew it by 5.9 MB; the hour's soak found it).
  class Records {
   public:
    class Iterator {
     public:
      Iterator(const Records& records, std::size_t i) : records_(&records), i_(i) {}
      Record operator*() const { return (*records_)[i_]; }
      Iterator& operator++() {
        ++i_;
        return *this;
      }
      bool operator!=(const Iterator& other) const { return i_ != other.i_; }

     private:
      const Records* records_;
      std::size_t i_;
    };

    explicit Records(std::uint32_t payload_words = 0) : payload_words_(payload_words) {}
    void reserve(std::size_t n) {
      times_.reserve(n);
      words_.reserve(n * payload_words_);
    }
    /// Appends a record: its words are filled in through the span returned.
    std::span<std::uint64_t> append(std::int64_t time_ns) {
      times_.push_back(time_ns);
      words_.resize(words_.size() + payload_words_);
      return {words_.data() + words_.size() - payload_words_, payload_words_};
    }
    /// Takes back the last record appended (overwritten while it was copied).
    void drop_last() {
      times_.pop_back();
      words_.resize(words_.size() - payload_words_);
    }
    [[nodiscard]] std::size_t size() const noexcept { return times_.size(); }
    [[nodiscard]] bool empty() const noexcept { return times_.empty(); }
    [[nodiscard]] Record operator[](std::size_t i) const {
      return {times_[i], std::span<const std::uint64_t>(words_.data() + i * payload_words_, payload_words_)};
    }
    [[nodiscard]] Record back() const { return (*this)[size() - 1]; }
    [[nodiscard]] Iterator begin() const { return {*this, 0}; }
    [[nodiscard]] Iterator end() const { return {*this, size()}; }

   private:
    std::uint32_t payload_words_;
    std::vector<std::int64_t> times_;
    std::vector<std::uint64_t> words_;
  };

  /// Declares a ring of `capacity` records of `payload_bytes` each (capacity >= 1); returns its
  /// number. Only before allocate(). Not real-time safe.
  std::size_t add(std::uint32_t capacity, std::uint32_t payload_bytes);
  HistoryRings() = default;
  HistoryRings(const HistoryRings&) = delete;
  HistoryRings& operator=(const HistoryRings&) = delete;
  HistoryRings(HistoryRings&&) = delete;
  HistoryRings& operator=(HistoryRings&&) = delete;
  ~HistoryRings();

  /// Allocates and zeroes the block for every ring declared, in this process's memory. Not
  /// real-time safe.
  void allocate();
  /// The same, in a memfd that other processes can map (fd()): reserved whole up front, so that a
  /// full tmpfs is this error, never a SIGBUS on a write. Not real-time safe.
  [[nodiscard]] Result<void> allocate_shared();
  /// Maps the block another process made by allocate_shared() with the same rings declared, open
  /// here as `fd` (the block keeps it); refused when its size is not this layout's. Not real-time
  /// safe.
  [[nodiscard]] Result<void> attach(int fd);
  /// The shared block's memfd (close-on-exec), -1 when the block is private or not yet made.
  [[nodiscard]] int fd() const noexcept { return fd_; }
  [[nodiscard]] std::size_t rings() const noexcept { return rings_.size(); }
  [[nodiscard]] const Ring& ring(std::size_t r) const noexcept { return rings_[r]; }
  /// Bytes of the block.
  [[nodiscard]] std::size_t bytes() const noexcept { return words_ * sizeof(std::uint64_t); }

  /// Writes one record: ring(r).payload_bytes bytes from `payload`, stamped `time_ns`. One writer
  /// per ring at a time (a change of writer goes through the caller's synchronisation). Real-time
  /// safe, wait-free: a bounded copy, no allocation.
  void write(std::size_t r, std::int64_t time_ns, const void* payload) noexcept;
  /// Records written to ring r so far (not all of them still held). Any thread.
  [[nodiscard]] std::uint64_t written(std::size_t r) const noexcept;
  /// The records ring r holds, oldest first, each whole. Not real-time safe (it allocates).
  [[nodiscard]] Records read(std::size_t r) const;

 private:
  Result<void> map_shared(const char* what);

  std::vector<Ring> rings_;
  std::size_t words_ = 0;
  // NOLINTNEXTLINE(cppcoreguidelines-avoid-c-arrays): one block of a size known only at allocate(), never resized
  std::unique_ptr<std::uint64_t[]> private_;  // the private block, when it is one
  std::uint64_t* block_ = nullptr;            // the block, private or mapped
  int fd_ = -1;                               // the shared block's memfd
};

}  // namespace chimera
