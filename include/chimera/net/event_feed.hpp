#pragma once
// What happened in a running subsystem, for the streams that ask for it (docs/control-api.md,
// "Streams"): tasks changing state, the subsystem's events (a task entering ERROR, a job overdue),
// switches with their record, and the illegal-configuration flag going up or down. Each item is
// numbered and kept in a bounded history: a stream sends what came after the last one it sent, and
// one that fell further behind than the history is told how many it missed. Nothing waits for a
// reader, and no real-time thread ever touches it.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "chimera/control/subsystem.hpp"
#include "chimera/exec/event.hpp"
#include "chimera/lifecycle/state.hpp"

namespace chimera::net {

class EventFeed {
 public:
  /// How many items the history keeps: at the rate of the busiest tests (a switch a millisecond
  /// for a second, four items each) a reader 50 ms behind still misses nothing.
  static constexpr std::size_t kCapacity = 1024;

  /// One item as its stream frame's "event" (JSON), and its number (from 0, never reused).
  struct Item {
    std::uint64_t seq = 0;
    std::string json;
  };

  /// Compares the subsystem with what it last saw: every task whose state changed, the switches
  /// carried out since, the flag if it moved; then `events` (drained by the caller, the feed's one
  /// source of them). Call it from the thread holding the command gate. Not real-time safe.
  void observe(const Subsystem& subsystem, const std::vector<Event>& events = {});

  /// The items numbered `from` and later, at most `max` of them, into `out` (cleared first); the
  /// number of those before that are no longer kept (0 when none was missed). Any thread.
  std::uint64_t since(std::uint64_t from, std::size_t max, std::vector<Item>& out) const;
  /// The number the next item will have: a stream that subscribes now starts there. Any thread.
  [[nodiscard]] std::uint64_t next_seq() const;
  /// How many switches the feed has seen, for the figures beside it. Any thread.
  [[nodiscard]] std::size_t switches() const { return switches_seen_.load(std::memory_order_relaxed); }

 private:
  void publish(std::string text);

  // What observe() saw last; only the gate's holder touches these.
  std::vector<std::pair<std::string, TaskState>> states_;
  std::atomic<std::size_t> switches_seen_{0};  // relaxed: a count for display, ordered with nothing
  bool flag_ = false;
  bool observed_ = false;  // the first observe() takes the states as they are: nothing changed yet

  mutable std::mutex mutex_;  // guards the history: held for a copy, never while sending
  std::vector<Item> ring_;    // item seq sits at seq % kCapacity
  std::uint64_t next_ = 0;
};

}  // namespace chimera::net
