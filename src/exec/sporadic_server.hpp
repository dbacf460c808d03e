#pragma once
// The sporadic server of an aperiodic task (paper 3.2, [25]): at most `budget` of execution per
// server period. What a job uses is charged when it ends and comes back one server period after
// the job started. Both executives run one per served task, on their own clock. Real-time safe:
// a fixed ring of pending refills; a refill that finds the ring full is merged into the last one,
// later, which never gives budget back early.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>

namespace chimera {

class SporadicServer {
 public:
  static constexpr std::size_t kMaxRefills = 64;
  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();

  /// The task turns on: a server with nothing pending starts with its full budget.
  void turn_on(std::int64_t budget) noexcept {
    if (count_ == 0 && budget_ <= 0) budget_ = budget;
  }
  /// Gives back every refill due at or before `now`.
  void refill(std::int64_t now) noexcept {
    while (count_ > 0 && ring_[head_].first <= now) {
      budget_ += ring_[head_].second;
      head_ = (head_ + 1) % kMaxRefills;
      --count_;
    }
  }
  /// A job that started at `start` used `used`: charged now, back at start + `server_period`.
  void charge(std::int64_t start, std::int64_t used, std::int64_t server_period) noexcept {
    budget_ -= used;
    const std::pair<std::int64_t, std::int64_t> back{start + server_period, used};
    if (count_ < kMaxRefills) {
      ring_[(head_ + count_) % kMaxRefills] = back;
      ++count_;
      return;
    }
    auto& last = ring_[(head_ + kMaxRefills - 1) % kMaxRefills];
    last = {std::max(last.first, back.first), last.second + back.second};  // merged, later: safe
  }

  /// A job may start only while some budget remains.
  [[nodiscard]] bool exhausted() const noexcept { return budget_ <= 0; }
  [[nodiscard]] std::int64_t budget() const noexcept { return budget_; }
  /// When the next refill is due; kNever if none is pending.
  [[nodiscard]] std::int64_t next_refill() const noexcept { return count_ > 0 ? ring_[head_].first : kNever; }
  [[nodiscard]] std::size_t pending() const noexcept { return count_; }

 private:
  std::array<std::pair<std::int64_t, std::int64_t>, kMaxRefills> ring_{};  // (due, amount), oldest first
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::int64_t budget_ = 0;
};

}  // namespace chimera
