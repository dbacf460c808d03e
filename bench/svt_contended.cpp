// Reader latency while a writer hammers the same 6-double variable from the other core: the
// state variable table's sequence protocol against a std::mutex-guarded copy. Each read is timed
// on its own with the TSC; the writer writes back to back for as long as the reader reads. Both
// threads run SCHED_FIFO (for about a second), so that other programs on this shared machine do
// not stop the writer and turn the test into an uncontended one.
//
//   svt_contended [--quick] [--out FILE] [--samples-dir DIR]
//
// Keys: svt_read_p99_contended_ns, mutex_read_p99_contended_ns, and the floor beneath both:
// cache_line_transfer_ns_p50, one cache line moving between the two cores.

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "chimera/svt/global_table.hpp"
#include "common/bench_util.hpp"

namespace chimera::bench {
namespace {

constexpr std::uint32_t kDoubles = 6;
constexpr int kReaderCpu = 0;
constexpr int kWriterCpu = 1;
constexpr int kPriority = 60;
constexpr std::uint64_t kWarmupWrites = 10'000;  // the writer is running flat out before timing starts

/// SCHED_FIFO for the calling thread (or back to SCHED_OTHER). A thread must not create another
/// while it is SCHED_FIFO and spinning: the new one inherits the policy and may wait forever for
/// the CPU of its creator before it can pin itself elsewhere.
bool set_fifo(bool on) {
  sched_param sp{};
  sp.sched_priority = on ? kPriority : 0;
  return pthread_setschedparam(pthread_self(), on ? SCHED_FIFO : SCHED_OTHER, &sp) == 0;
}

struct Run {
  std::vector<std::uint32_t> ns;
  std::uint64_t writes = 0;
  std::uint64_t reads_new = 0;  // reads that copied a newer value (svt) / every read (mutex)
  bool realtime = false;        // SCHED_FIFO granted
};

/// Runs `writer_step` in a loop on the writer's CPU while `read` is timed `n` times on this one.
template <class Read, class WriterStep>
Run contend(const TscClock& tsc, std::size_t n, Read read, WriterStep writer_step) {
  Run run;
  run.ns.resize(n);
  std::atomic<bool> stop{false};
  std::atomic<bool> started{false};
  std::uint64_t writes = 0;
  std::thread writer([&] {
    pin_to_cpu(kWriterCpu);
    set_fifo(true);
    while (!stop.load(std::memory_order_relaxed)) {  // relaxed: a stop flag, nothing to publish
      writer_step();
      if (++writes == kWarmupWrites) started.store(true, std::memory_order_release);  // release: go
    }
  });
  run.realtime = set_fifo(true);
  while (!started.load(std::memory_order_acquire)) {  // acquire: pairs with the writer's release
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t a = TscClock::stamp();
    run.reads_new += read() ? 1 : 0;
    const std::uint64_t b = TscClock::stamp();
    run.ns[i] = tsc.ns(a, b);
  }
  set_fifo(false);
  stop.store(true, std::memory_order_relaxed);
  writer.join();
  run.writes = writes;
  return run;
}

/// The hardware's floor for the figures above: one cache line moving from one core to the other.
/// Two threads bounce a counter on its own line, each waiting for the other's increment; a round
/// trip is two transfers. Returns the one-way time of each of `n` round trips.
std::vector<std::uint32_t> line_transfers(const TscClock& tsc, std::size_t n) {
  struct alignas(64) Line {
    std::atomic<std::uint64_t> value{0};
  };
  Line line;
  std::thread echo([&] {
    pin_to_cpu(kWriterCpu);
    set_fifo(true);
    for (std::uint64_t k = 1; k < 2 * n; k += 2) {
      // Acquire and release: a ping-pong, each side's store is what the other waits for.
      while (line.value.load(std::memory_order_acquire) != k) {
      }
      line.value.store(k + 1, std::memory_order_release);
    }
  });
  std::vector<std::uint32_t> ns(n);
  set_fifo(true);
  for (std::uint64_t i = 0; i < n; ++i) {
    const std::uint64_t a = TscClock::stamp();
    line.value.store(2 * i + 1, std::memory_order_release);            // release: hands the line over
    while (line.value.load(std::memory_order_acquire) != 2 * i + 2) {  // acquire: the echo's store
    }
    const std::uint64_t b = TscClock::stamp();
    ns[i] = tsc.ns(a, b) / 2;
  }
  set_fifo(false);
  echo.join();
  return ns;
}

nlohmann::json describe(Run& run) {
  auto j = summary(run.ns);
  j["writes_during_run"] = run.writes;
  j["reads_that_copied_a_new_value"] = run.reads_new;
  j["sched_fifo"] = run.realtime;
  return j;
}

}  // namespace
}  // namespace chimera::bench

int main(int argc, char** argv) {
  using namespace chimera;
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  const std::size_t n = args.quick ? 200'000 : 2'000'000;
  pin_to_cpu(kReaderCpu);
  const TscClock tsc = TscClock::calibrate();
  Fragment out;

  // The state variable table, in POSIX shared memory as a subsystem has it.
  auto table = GlobalTable::create("bench_contended_" + std::to_string(::getpid()),
                                   std::vector<VarSpec>{{"x", {ElemType::kF64, kDoubles}}});
  if (!table) {
    std::fprintf(stderr, "%s\n", table.error().message.c_str());
    return 1;
  }
  std::array<double, kDoubles> written{};
  std::array<double, kDoubles> got{};
  table->write(0, written.data());
  std::uint64_t seen = 0;
  double counter = 0;
  Run svt = contend(
      tsc, n,
      [&] {
        const ReadOutcome r = table->read(0, got.data(), seen);
        seen = r.version;
        return r.freshness == Freshness::kNew;
      },
      [&] {
        written[0] = ++counter;
        table->write(0, written.data());
      });

  // The comparison: the same 48 bytes under a std::mutex, as a naive shared variable has them.
  std::mutex mutex;
  std::array<double, kDoubles> guarded{};
  Run mtx = contend(
      tsc, n,
      [&] {
        std::lock_guard lock(mutex);
        std::memcpy(got.data(), guarded.data(), sizeof(guarded));
        return true;
      },
      [&] {
        written[0] = ++counter;
        std::lock_guard lock(mutex);
        std::memcpy(guarded.data(), written.data(), sizeof(guarded));
      });

  std::vector<std::uint32_t> transfers = line_transfers(tsc, n / 10);
  out.details()["cache_line_transfer"] = summary(transfers);

  out.samples(args, "contended_svt", svt.ns);
  out.samples(args, "contended_mutex", mtx.ns);
  out.details()["svt"] = describe(svt);
  out.details()["mutex"] = describe(mtx);
  out.details()["tsc_ns_per_tick"] = tsc.ns_per_tick();
  out.details()["stopwatch_overhead_ns_subtracted"] = tsc.overhead_ns();
  out.details()["reader_cpu"] = kReaderCpu;
  out.details()["writer_cpu"] = kWriterCpu;
  out.result("svt_read_p99_contended_ns", out.details()["svt"]["p99"].get<double>());
  out.result("mutex_read_p99_contended_ns", out.details()["mutex"]["p99"].get<double>());
  out.result("cache_line_transfer_ns_p50", out.details()["cache_line_transfer"]["p50"].get<double>());
  out.result("svt_read_p50_contended_ns", out.details()["svt"]["p50"].get<double>());
  out.result("mutex_read_p50_contended_ns", out.details()["mutex"]["p50"].get<double>());
  return out.write(args);
}
