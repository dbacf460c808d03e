#pragma once
// The messages between the main process and a module process (docs/processes.md), over a
// SOCK_SEQPACKET socket pair: one fixed-size command, one fixed-size reply. Plain data: no
// pointer, no std::string. Exported to the parts above (the worker's main loop).

#include <array>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "chimera/core/result.hpp"
#include "chimera/lifecycle/state.hpp"

namespace chimera {

enum class ProcessCommandKind : std::uint32_t {
  kSignal,          // tasks[0]: carry out `signal`
  kTurnOnTogether,  // tasks[0..count): on as one (Executive::turn_on_together)
  kReinit,          // tasks[0]: reinit() between two cycles
  kQuit,            // every task off and killed, then exit 0
  kCommit,          // one part of a switch (SwitchCommit): tasks leave, joining join, target the plan
};

struct ProcessCommand {
  static constexpr std::size_t kMaxTasks = 256;
  ProcessCommandKind kind = ProcessCommandKind::kSignal;
  Signal signal = Signal::kSpawn;
  std::uint32_t count = 0;
  std::array<std::uint32_t, kMaxTasks> tasks{};
  // kCommit: `tasks` leave; these join; the target configuration's tasks; the instant and part.
  std::uint32_t joining_count = 0;
  std::array<std::uint32_t, kMaxTasks> joining{};
  std::uint32_t target_count = 0;
  std::array<std::uint32_t, kMaxTasks> target{};
  std::int64_t at_ns = -1;
  std::uint8_t part = 0;  // SwitchCommit::Part
};

/// The answer to a command, and the worker's first message (ready, or why it cannot run).
struct ProcessReply {
  std::uint32_t ok = 1;
  Errc code = Errc::kSystem;
  std::array<char, 512> message{};
  std::int64_t value = -1;  // kCommit: CommitOutcome::joins_from_ns

  static ProcessReply from(const Result<void>& r, std::int64_t value = -1) {
    ProcessReply reply;
    reply.value = value;
    if (r) return reply;
    reply.ok = 0;
    reply.code = r.error().code;
    const std::string_view text = r.error().message;
    const std::size_t n = std::min(text.size(), reply.message.size() - 1);
    std::memcpy(reply.message.data(), text.data(), n);
    return reply;
  }
  [[nodiscard]] Result<void> result() const {
    if (ok != 0) return {};
    return make_error(code, std::string(message.data()));
  }
};

}  // namespace chimera
