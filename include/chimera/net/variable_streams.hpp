#pragma once
// WebSocket streams of state variables (docs/control-api.md, "Streams"): a client names
// variables and a rate; a thread of its own, an ordinary one, samples them from the table at that
// rate and sends the latest values. Nothing is queued: a client that reads slowly gets fewer
// samples, a stalled one blocks only its own thread, and no task ever waits for either.

#include <pthread.h>

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/net/control_gate.hpp"

struct mg_connection;

namespace chimera::net {

class VariableStream {
 public:
  static constexpr double kMaxRateHz = 1000.0;
  static constexpr double kMinRateHz = 0.1;
  static constexpr std::size_t kMaxVariables = 64;

  /// Starts the stream's thread on `conn` (an open WebSocket); it sends nothing until subscribe().
  VariableStream(ControlGate& gate, mg_connection* conn);
  /// Stops and joins the thread (within the write timeout if the client is stalled).
  ~VariableStream();
  VariableStream(const VariableStream&) = delete;
  VariableStream& operator=(const VariableStream&) = delete;

  /// Why the stream could not start (its thread would not start): it has told the client and
  /// sent the close frame. Empty when it runs.
  [[nodiscard]] const std::string& failure() const { return failure_; }

  /// Handles one text frame from the client: {"variables": [...], "rate_hz": R}. The reply (an
  /// ack or an error) is sent by the stream's thread, the only writer. Not real-time safe.
  void receive(std::string_view text);

 private:
  void run();
  [[nodiscard]] std::string sample(const std::vector<std::string>& variables, std::uint64_t seq,
                                   std::int64_t t_ns) const;
  bool send(const std::string& text);

  ControlGate& gate_;
  mg_connection* conn_;
  std::mutex mutex_;  // guards the fields below; never held while sending
  std::condition_variable changed_;
  std::vector<std::string> variables_;
  std::int64_t period_ns_ = 0;  // 0: not subscribed
  std::string pending_reply_;   // the latest reply to a subscription, sent before the next sample
  bool stopping_ = false;
  // A thread of a small stack, not std::thread's 8 MiB: the real clock's mlockall(MCL_FUTURE)
  // makes every new thread's whole stack resident, and 32 streams took 256 MiB that way.
  pthread_t thread_{};
  bool started_ = false;
  std::string failure_;
};

}  // namespace chimera::net
