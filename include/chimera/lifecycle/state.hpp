#pragma once
// The lifecycle of a port-based object (paper 3.3, Figure 7): states, signals, and which
// signal is allowed in which state. docs/lifecycle.md draws it.

#include <cstdint>
#include <optional>
#include <string_view>

namespace chimera {

enum class TaskState : std::uint8_t { kNotCreated, kOff, kOn, kError };
enum class Signal : std::uint8_t { kSpawn, kOn, kOff, kKill, kClear };

constexpr std::string_view state_name(TaskState s) noexcept {
  switch (s) {
    case TaskState::kNotCreated: return "NOT-CREATED";
    case TaskState::kOff: return "OFF";
    case TaskState::kOn: return "ON";
    case TaskState::kError: return "ERROR";
  }
  return "?";
}

constexpr std::string_view signal_name(Signal s) noexcept {
  switch (s) {
    case Signal::kSpawn: return "spawn";
    case Signal::kOn: return "on";
    case Signal::kOff: return "off";
    case Signal::kKill: return "kill";
    case Signal::kClear: return "clear";
  }
  return "?";
}

std::optional<Signal> parse_signal(std::string_view name) noexcept;

/// The state a signal leads to when every method it calls succeeds, or nothing if the signal is
/// not allowed in `from`. Failures are handled by the task (init failing stays NOT-CREATED,
/// clear failing stays ERROR, other failures go through error()).
///   NOT-CREATED --spawn (init)--> OFF      OFF --on (on)--> ON       ON --off (off)--> OFF
///   OFF --kill (kill)--> NOT-CREATED       ERROR --clear (clear)--> OFF
///   ERROR --kill (kill)--> NOT-CREATED     ON --kill (off, kill)--> NOT-CREATED
constexpr std::optional<TaskState> transition(TaskState from, Signal signal) noexcept {
  using S = TaskState;
  switch (signal) {
    case Signal::kSpawn: return from == S::kNotCreated ? std::optional(S::kOff) : std::nullopt;
    case Signal::kOn: return from == S::kOff ? std::optional(S::kOn) : std::nullopt;
    case Signal::kOff: return from == S::kOn ? std::optional(S::kOff) : std::nullopt;
    case Signal::kKill: return from != S::kNotCreated ? std::optional(S::kNotCreated) : std::nullopt;
    case Signal::kClear: return from == S::kError ? std::optional(S::kOff) : std::nullopt;
  }
  return std::nullopt;
}

}  // namespace chimera
