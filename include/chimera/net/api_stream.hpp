#pragma once
// One WebSocket stream of a running subsystem (docs/control-api.md, "Streams"): a client names
// what it wants to watch, state variables at a rate, the tasks' timing at a rate, and what happens
// (state changes, events, switches, the illegal-configuration flag); a thread of its own, an
// ordinary one, reads them from the table, the tasks' counters and the gate's feed, and sends the
// latest. Nothing is queued for the client: one that reads slowly gets fewer samples, a stalled one
// blocks only its own thread, and no task ever waits for either.

#include <pthread.h>

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "chimera/net/control_gate.hpp"

struct mg_connection;

namespace chimera::net {

/// What a client asked its stream for; what it did not ask for is off (a period of 0).
struct Subscription {
  std::vector<std::string> variables;
  std::int64_t sample_period_ns = 0;
  /// Samples sent together, one "samples" frame per this period (batch_hz); 0: one "sample"
  /// frame per sample. A page draws at 60 Hz at most: a thousand frames a second cost the
  /// machine (and the real-time tasks beside it) what thirty carrying the same samples do not.
  std::int64_t batch_period_ns = 0;
  std::int64_t timing_period_ns = 0;
  std::vector<std::string> timing_tasks;  // empty: every task
  bool events = false;
};

class ApiStream {
 public:
  static constexpr double kMaxRateHz = 1000.0;
  static constexpr double kMinRateHz = 0.1;
  static constexpr double kMaxTimingHz = 10.0;  // a thousand tasks' figures at most ten times a second
  static constexpr std::size_t kMaxVariables = 64;
  /// A batch is sent when it holds this many samples, whatever batch_hz says.
  static constexpr std::size_t kMaxBatchSamples = 1000;
  /// How often the feed is looked at for new events: the gate's feed is filled about as often.
  static constexpr std::int64_t kEventPollNs = 20'000'000;

  /// Starts the stream's thread on `conn` (an open WebSocket); it sends nothing until subscribe().
  ApiStream(ControlGate& gate, mg_connection* conn);
  /// Stops and joins the thread (within the write timeout if the client is stalled).
  ~ApiStream();
  ApiStream(const ApiStream&) = delete;
  ApiStream& operator=(const ApiStream&) = delete;

  /// Why the stream could not start (its thread would not start): it has told the client and
  /// sent the close frame. Empty when it runs.
  [[nodiscard]] const std::string& failure() const { return failure_; }

  /// Handles one text frame from the client, a subscription that replaces the one before. The
  /// reply (an ack or an error) is sent by the stream's thread, the only writer. Not real-time safe.
  void receive(std::string_view text);

 private:
  void run();
  [[nodiscard]] std::string sample(const std::vector<std::string>& variables, std::uint64_t seq,
                                   std::int64_t t_ns) const;
  /// The samples taken since the last "samples" frame, as that frame's parts already in JSON:
  /// each sample is formatted as it is taken, so that a frame of a thousand costs no more than
  /// its samples did one by one (formatted at once, a frame held the thread past a sample's time).
  struct Batch {
    std::uint64_t first_seq = 0;
    std::size_t count = 0;
    std::string t_ns;                 // the times, comma-separated
    std::vector<std::string> values;  // per variable, its value (or null) per sample, comma-separated
  };
  void add_to_batch(Batch& batch, const std::vector<std::string>& variables, std::uint64_t seq,
                    std::int64_t t_ns) const;
  static std::string take_batch(Batch& batch, const std::vector<std::string>& variables);
  [[nodiscard]] std::string timing(const std::vector<std::string>& tasks, std::uint64_t seq, std::int64_t t_ns) const;
  /// Sends the feed's items from `cursor` on (and moves it past them); false if the client is gone.
  bool send_events(std::uint64_t& cursor);
  bool send(const std::string& text);

  ControlGate& gate_;
  mg_connection* conn_;
  std::mutex mutex_;  // guards the fields below; never held while sending
  std::condition_variable changed_;
  Subscription wanted_;
  std::uint64_t generation_ = 0;  // counts accepted subscriptions: the thread restarts its clocks on each
  std::string pending_reply_;     // the latest reply to a subscription, sent before the next frame
  bool stopping_ = false;
  // A thread of a small stack, not std::thread's 8 MiB: the real clock's mlockall(MCL_FUTURE)
  // makes every new thread's whole stack resident, and 32 streams took 256 MiB that way.
  pthread_t thread_{};
  bool started_ = false;
  std::string failure_;
};

}  // namespace chimera::net
