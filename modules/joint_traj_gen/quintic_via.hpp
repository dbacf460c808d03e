#pragma once
// The joint_traj_gen module's motion law, apart from the framework so that tests and tools can
// use it directly: quintic segments through via points, with rests between them.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace chimera::modules {

/// A path from a start position through via points (each ndof joint values), one quintic
/// polynomial per segment with zero velocity and acceleration at both ends (Craig 1989, 7.3),
/// a rest of hold time at each via point, and optionally round again from the last via point to
/// the first, forever.
class QuinticVia {
 public:
  /// Allocates; not real-time safe. `vias` holds the via points one after another (n x ndof).
  void configure(std::size_t ndof, std::vector<double> vias, std::int64_t segment_ns, std::int64_t hold_ns, bool loop) {
    ndof_ = ndof;
    vias_ = std::move(vias);
    count_ = ndof == 0 ? 0 : vias_.size() / ndof;
    segment_ns_ = segment_ns;
    hold_ns_ = hold_ns;
    loop_ = loop;
    start_.assign(ndof, 0.0);
  }

  /// Sets where the path starts (missing entries zero). Real-time safe.
  void restart(std::span<const double> start) noexcept {
    for (std::size_t i = 0; i < ndof_; ++i) start_[i] = i < start.size() ? start[i] : 0.0;
  }

  /// Position and velocity at t_ns after the start (t_ns >= 0). Real-time safe.
  void sample(std::int64_t t_ns, std::span<double> pos, std::span<double> vel) const noexcept {
    const std::int64_t leg_ns = segment_ns_ + hold_ns_;  // one move and the rest after it
    const double* from = start_.data();
    const double* to = count_ > 0 ? via(0) : start_.data();
    std::int64_t local_ns = t_ns;
    if (t_ns >= leg_ns && count_ > 0) {
      // Integer time keeps the segment boundaries exact however long the path has run.
      const std::int64_t after = t_ns - leg_ns;
      const auto leg = static_cast<std::size_t>(after / leg_ns);
      local_ns = after % leg_ns;
      if (loop_) {
        from = via(leg % count_);
        to = via((leg + 1) % count_);
      } else if (leg + 1 < count_) {
        from = via(leg);
        to = via(leg + 1);
      } else {
        from = to = via(count_ - 1);
      }
    }
    if (local_ns >= segment_ns_) {
      for (std::size_t i = 0; i < ndof_; ++i) {
        pos[i] = to[i];
        vel[i] = 0.0;
      }
      return;
    }
    const double seg_s = static_cast<double>(segment_ns_) * 1e-9;
    const double u = static_cast<double>(local_ns) / static_cast<double>(segment_ns_);
    // s(u) = 10u^3 - 15u^4 + 6u^5: s, s' and s'' are 0 at u = 0 and 1, 0, 0 at u = 1.
    const double u2 = u * u;
    const double s = u2 * u * (10.0 + u * (-15.0 + 6.0 * u));
    const double ds = u2 * (30.0 + u * (-60.0 + 30.0 * u)) / seg_s;
    for (std::size_t i = 0; i < ndof_; ++i) {
      const double d = to[i] - from[i];
      pos[i] = from[i] + d * s;
      vel[i] = d * ds;
    }
  }

  [[nodiscard]] std::size_t via_count() const noexcept { return count_; }

 private:
  [[nodiscard]] const double* via(std::size_t k) const noexcept { return vias_.data() + k * ndof_; }

  std::size_t ndof_ = 0;
  std::vector<double> vias_;
  std::size_t count_ = 0;
  std::vector<double> start_;
  std::int64_t segment_ns_ = 1;
  std::int64_t hold_ns_ = 0;
  bool loop_ = true;
};

}  // namespace chimera::modules
