#include "chimera/lifecycle/state.hpp"

#include <gtest/gtest.h>

namespace chimera {
namespace {

constexpr TaskState kStates[] = {TaskState::kNotCreated, TaskState::kOff, TaskState::kOn, TaskState::kError};
constexpr Signal kSignals[] = {Signal::kSpawn, Signal::kOn, Signal::kOff, Signal::kKill, Signal::kClear};

// The whole of Figure 7's table: every state against every signal.
TEST(LifecycleState, TransitionTableMatchesFigure7) {
  using S = TaskState;
  struct Row {
    S from;
    Signal signal;
    std::optional<S> to;
  };
  const Row expected[] = {
      {S::kNotCreated, Signal::kSpawn, S::kOff},
      {S::kNotCreated, Signal::kOn, {}},
      {S::kNotCreated, Signal::kOff, {}},
      {S::kNotCreated, Signal::kKill, {}},
      {S::kNotCreated, Signal::kClear, {}},
      {S::kOff, Signal::kSpawn, {}},
      {S::kOff, Signal::kOn, S::kOn},
      {S::kOff, Signal::kOff, {}},
      {S::kOff, Signal::kKill, S::kNotCreated},
      {S::kOff, Signal::kClear, {}},
      {S::kOn, Signal::kSpawn, {}},
      {S::kOn, Signal::kOn, {}},
      {S::kOn, Signal::kOff, S::kOff},
      {S::kOn, Signal::kKill, S::kNotCreated},
      {S::kOn, Signal::kClear, {}},
      {S::kError, Signal::kSpawn, {}},
      {S::kError, Signal::kOn, {}},
      {S::kError, Signal::kOff, {}},
      {S::kError, Signal::kKill, S::kNotCreated},
      {S::kError, Signal::kClear, S::kOff},
  };
  int checked = 0;
  for (const S s : kStates)
    for (const Signal g : kSignals)
      for (const Row& r : expected)
        if (r.from == s && r.signal == g) {
          EXPECT_EQ(transition(s, g), r.to) << state_name(s) << " --" << signal_name(g);
          ++checked;
        }
  EXPECT_EQ(checked, 20);
}

TEST(LifecycleState, NamesRoundTrip) {
  for (const Signal g : kSignals) EXPECT_EQ(parse_signal(signal_name(g)), g);
  EXPECT_EQ(parse_signal("reboot"), std::nullopt);
  EXPECT_EQ(state_name(TaskState::kNotCreated), "NOT-CREATED");
  EXPECT_EQ(state_name(TaskState::kError), "ERROR");
}

}  // namespace
}  // namespace chimera
