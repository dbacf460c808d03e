#pragma once
// The teleoperation commands, one a line or a datagram, as text an operator, a script or a
// keyboard sends:
//
//   move dx dy dz [drx dry drz]   step the goal (m; rad, a rotation about the base axes)
//   goto x y z rx ry rz           set the goal (m; rotation vector, rad)
//   vel vx vy vz [wx wy wz]       move the goal at this velocity (m/s; rad/s) until stop, another
//                                 command, or `timeout` without any command (a dead man's switch)
//   stop                          stop a vel motion; the goal stays where it got to
//   hold                          the goal to where the tool is (x_m) now
//   home                          the goal back to the tool's pose when the task was turned on
//
// Parsing allocates nothing and throws nothing: it runs in the real-time cycle.

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <string_view>

namespace chimera::modules::teleop {

enum class Verb { kMove, kGoto, kVel, kStop, kHold, kHome };

struct Command {
  Verb verb = Verb::kStop;
  std::array<double, 6> values{};  // missing rotation parts are 0
};

namespace detail {
constexpr bool blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ','; }

// The next word of `text` from `at`, or an empty view at the end.
inline std::string_view next_word(std::string_view text, std::size_t& at) noexcept {
  while (at < text.size() && blank(text[at])) ++at;
  const std::size_t start = at;
  while (at < text.size() && !blank(text[at])) ++at;
  return text.substr(start, at - start);
}

// Each verb and how many numbers it takes: `least`, or `most` (the rotation part added).
struct Shape {
  std::string_view word;
  Verb verb;
  std::size_t least;
  std::size_t most;
};
inline constexpr std::array<Shape, 6> kShapes{{{"move", Verb::kMove, 3, 6},
                                               {"goto", Verb::kGoto, 6, 6},
                                               {"vel", Verb::kVel, 3, 6},
                                               {"stop", Verb::kStop, 0, 0},
                                               {"hold", Verb::kHold, 0, 0},
                                               {"home", Verb::kHome, 0, 0}}};
}  // namespace detail

/// The command of one line; false for anything else (an unknown verb, a wrong count of numbers,
/// a number that is not finite).
inline bool parse_command(std::string_view text, Command& out) noexcept {
  std::size_t at = 0;
  const std::string_view verb = detail::next_word(text, at);
  const auto* shape = std::find_if(detail::kShapes.begin(), detail::kShapes.end(),
                                   [&](const detail::Shape& s) { return s.word == verb; });
  if (shape == detail::kShapes.end()) return false;
  out.verb = shape->verb;
  out.values.fill(0.0);
  std::size_t count = 0;
  for (std::string_view word = detail::next_word(text, at); !word.empty(); word = detail::next_word(text, at)) {
    if (count == shape->most) return false;
    if (word.front() == '+') word.remove_prefix(1);
    double v = 0.0;
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
    if (ec != std::errc() || end != word.data() + word.size() || !std::isfinite(v)) return false;
    out.values[count++] = v;
  }
  return count == shape->least || count == shape->most;
}

}  // namespace chimera::modules::teleop
