// data_logger: the paper's data logger (section 3), a task that only gathers data and so has no
// output ports. Each cycle copies the chosen variables into a preallocated ring; an ordinary
// thread drains the ring into a CSV file, so the real-time path never formats, writes or waits.
// A file that cannot be written (a full disk) is said at once, its lost rows counted, and the
// task's kill reports them, so that the run does not end as if its log were whole.

#include "module_docs/data_logger.hpp"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "chimera/module/registry.hpp"
#include "row_ring.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

constexpr std::size_t kMinRows = 1024;
constexpr auto kDrainPeriod = std::chrono::milliseconds(20);
constexpr auto kWaitForRoom = std::chrono::microseconds(20);
constexpr std::size_t kWriteChunk = std::size_t{64} * 1024;  // bytes formatted before one fwrite
// The ring's bound in bytes: `capacity` counts rows, whose width the variables set, so the rows
// alone do not bound the memory (1e8 rows of 19 doubles would be 15 GB).
constexpr std::size_t kMaxRingBytes = std::size_t{1} << 30;

// The variables to record, each once, in the order given.
StringList variables_of(const Params& p) {
  StringList out;
  for (auto& v : p.strings("variables"))
    if (std::find(out.begin(), out.end(), v) == out.end()) out.push_back(std::move(v));
  return out;
}

// Where the CSV goes: `file`, or <task>.csv; a relative path below $CHIMERA_LOG_DIR if it is set.
std::string log_path(const Params& p, std::string_view task) {
  const std::string file = p.text("file");
  return log_file_path(file.empty() ? std::string(task) + ".csv" : file);
}

// The writer is an ordinary thread, whatever the task's thread is: it must not inherit SCHED_FIFO
// or the task's CPU (threads inherit both from their creator).
void become_ordinary_thread() {
  sched_param normal{};
  normal.sched_priority = 0;
  (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
  cpu_set_t all;
  CPU_ZERO(&all);
  if (sched_getaffinity(::getpid(), sizeof(all), &all) == 0)  // the process's (main thread's) CPUs
    (void)pthread_setaffinity_np(pthread_self(), sizeof(all), &all);
}

class DataLogger final : public Module {
 public:
  static constexpr const char* kName = "data_logger";
  static constexpr const char* kSummary = docs::data_logger::kSummary;
  static constexpr const char* kDoc = docs::data_logger::kText;

  static void declare(Declarations& d, const Params& p) {
    for (const auto& v : variables_of(p)) d.in_var(v, Dim::follow(), "recorded, every element each cycle");
    d.param("variables", StringList{}, "", "state variables to record (one in-var port each)");
    d.param("file", std::string(), "", "CSV file; empty: <task>.csv; relative: below $CHIMERA_LOG_DIR if set");
    d.param("capacity", 0.0, "rows", "ring size; 0: one second of rows at the task's period, at least 1024")
        .whole()
        .at_least(0)
        .at_most(1e8);
    d.resource("a CSV file, written by an ordinary (not real-time) thread");
  }

  ~DataLogger() override { stop_writer(); }
  DataLogger() = default;
  DataLogger(const DataLogger&) = delete;
  DataLogger& operator=(const DataLogger&) = delete;
  DataLogger(DataLogger&&) = delete;
  DataLogger& operator=(DataLogger&&) = delete;

 protected:
  Status init(InitContext& ctx) override {
    const Params& p = ctx.params();
    names_ = variables_of(p);
    if (names_.empty()) return ctx.refuse("variables", "give variables: [names] to record");
    std::size_t width = 1;  // t
    for (const auto& name : names_) {
      inputs_.push_back(ctx.in<double>(name));
      width += inputs_.back().size();
    }
    if (ctx.failed()) return Status::ok();  // the framework reports the port that did not bind

    const double capacity = p.number("capacity", 0.0);
    if (!(capacity >= 0.0) || capacity > 1e8 || capacity != std::floor(capacity))
      return ctx.refuse("capacity", "capacity must be a whole number of rows from 0 to 1e8");
    const std::size_t most_rows = kMaxRingBytes / (width * sizeof(double));
    std::size_t rows = static_cast<std::size_t>(capacity);
    if (rows > most_rows)
      return ctx.refuse("capacity", intern(fmt::format("{} rows of {} values take {} MiB, past the ring's {} MiB: "
                                                       "at most {} rows",
                                                       rows, width, rows * width * sizeof(double) >> 20,
                                                       kMaxRingBytes >> 20, most_rows)));
    if (rows == 0) {
      // One second of rows, within the bound: a tiny period must not size a billion rows.
      const double period = ctx.period_s();
      const double per_second = period > 0.0 ? std::ceil(1.0 / period) : 0.0;
      rows = std::min(most_rows, std::max(kMinRows, static_cast<std::size_t>(per_second)));
    }
    ring_ = std::make_unique<RowRing>(rows, width);

    path_ = log_path(p, ctx.task_name());
    task_ = std::string(ctx.task_name());
    file_ = std::fopen(path_.c_str(), "w");
    if (file_ == nullptr)
      return ctx.refuse(
          "file", intern(fmt::format("cannot write the log {}: {}", path_, std::generic_category().message(errno))));
    // Unbuffered: out_ is the buffer, so each write's outcome is known at once, with its rows.
    (void)std::setvbuf(file_, nullptr, _IONBF, 0);
    out_.reserve(kWriteChunk + 4096);
    write_header();
    // A file that takes nothing (a full disk, /dev/full) is refused before the run starts.
    if (write_failed_)
      return ctx.refuse("file", intern(fmt::format("cannot write the log {}: {}", path_, write_error_)));
    timing_ = &ctx.timing();
    writing_ = true;  // before the thread: its start makes it visible there
    writer_ = std::thread([this] { write_loop(); });
    return Status::ok();
  }

  // Real-time: copies into the ring, never waits on the real clock.
  Status cycle() override {
    double* row = ring_->claim();
    if (row == nullptr) {
      if (!timing_->virtual_clock) {
        dropped_.fetch_add(1, std::memory_order_relaxed);  // a counter; read once at kill
        return Status::ok();
      }
      row = wait_for_room();
      if (row == nullptr) {  // the writer has stopped: waiting would never end
        dropped_.fetch_add(1, std::memory_order_relaxed);
        return Status::ok();
      }
    }
    row[0] = static_cast<double>(timing_->release_ns) / 1e9;  // correctly rounded: 0.03, not 0.030000000000000002
    std::size_t at = 1;
    for (const auto& in : inputs_) {
      const bool data = in.has_data();
      for (std::size_t i = 0; i < in.size(); ++i) row[at++] = data ? in[i] : std::numeric_limits<double>::quiet_NaN();
    }
    ring_->publish();
    return Status::ok();
  }

  Status kill() override {
    stop_writer();
    // The log is not whole: the run must not end as if it were (chimera run exits 1 on this).
    // (A header that could not be written failed init, which said so.)
    if (write_failed_ && writing_)
      return Status::fail(intern(fmt::format("{} rows lost: the log {} could not be written from t = {} s on: {}",
                                             lost_rows_ + dropped(), path_, first_lost_t_, write_error_)));
    if (!failure_.empty()) return Status::fail(intern(fmt::format("the log {} is incomplete: {}", path_, failure_)));
    if (dropped() > 0)
      return Status::fail(
          intern(fmt::format("{} rows lost: not logged to {}, the ring of {} rows was full (the "
                             "writer fell behind: raise capacity)",
                             dropped(), path_, ring_->rows())));
    return Status::ok();
  }

 private:
  // Virtual clock only: no deadline is real there, so the cycle waits for the writer, unless the
  // writer has given up (nullptr).
  double* wait_for_room() noexcept {
    for (;;) {
      wake_writer();
      std::this_thread::sleep_for(kWaitForRoom);
      if (double* row = ring_->claim()) return row;
      // acquire: pairs with the writer's release when it gives up
      if (writer_gone_.load(std::memory_order_acquire)) return nullptr;
    }
  }

  // Rows the cycle dropped because the ring was full; read once the writer has stopped.
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

  void wake_writer() noexcept {
    {
      const std::lock_guard lock(mutex_);
      wake_ = true;
    }
    wake_cv_.notify_one();
  }

  void write_header() {
    out_.clear();
    fmt::format_to(std::back_inserter(out_), "t");
    for (std::size_t v = 0; v < names_.size(); ++v) {
      const std::size_t n = inputs_[v].size();
      for (std::size_t i = 0; i < n; ++i) {
        if (n == 1)
          fmt::format_to(std::back_inserter(out_), ",{}", names_[v]);
        else
          fmt::format_to(std::back_inserter(out_), ",{}[{}]", names_[v], i);
      }
    }
    out_.push_back('\n');
    flush_out();
  }

  // Writes what out_ holds. The first failure (a full disk) is said at once; from then on the
  // rows are only counted, so that the ring keeps draining and the cycle never waits on a file
  // that will not take them.
  void flush_out() {
    if (!out_.empty() && !write_failed_ && std::fwrite(out_.data(), 1, out_.size(), file_) != out_.size())
      note_write_failure(errno);
    out_.clear();
    rows_in_out_ = 0;
  }

  void note_write_failure(int error) {
    write_failed_ = true;
    write_error_ = std::generic_category().message(error);
    // The rows of the chunk being written are lost (some of their lines may be in the file, cut).
    lost_rows_ += rows_in_out_;
    first_lost_t_ = chunk_first_t_;
    if (!writing_) return;  // the header, in init: init says it
    spdlog::error(
        "{}: cannot write the log {}: {}; its rows from t = {} s on are lost (counted; the run reports them "
        "at exit)",
        task_, path_, write_error_, first_lost_t_);
  }

  // Formats every row the ring holds. In steady state it allocates nothing: the buffer keeps its
  // capacity (the FILE has none).
  void drain() {
    ring_->drain([&](const double* row) {
      if (write_failed_) {
        ++lost_rows_;
        return;
      }
      if (rows_in_out_ == 0) chunk_first_t_ = row[0];
      for (std::size_t i = 0; i < ring_->width(); ++i) {
        if (i != 0) out_.push_back(',');
        fmt::format_to(std::back_inserter(out_), "{}", row[i]);
      }
      out_.push_back('\n');
      ++rows_in_out_;
      if (out_.size() >= kWriteChunk) flush_out();
    });
    flush_out();
  }

  void write_loop() {
    become_ordinary_thread();
    try {
      std::unique_lock lock(mutex_);
      while (!stop_) {
        lock.unlock();
        drain();
        lock.lock();
        wake_cv_.wait_for(lock, kDrainPeriod, [this] { return stop_ || wake_; });
        wake_ = false;
      }
      lock.unlock();
      drain();  // what the last cycles left
    } catch (const std::exception& e) {
      // Out of memory while formatting: the log ends here, the subsystem runs on.
      failure_ = e.what();
    }
    writer_gone_.store(true, std::memory_order_release);  // release: failure_ is written before
  }

  void stop_writer() noexcept {
    if (writer_.joinable()) {
      {
        const std::lock_guard lock(mutex_);
        stop_ = true;
      }
      wake_cv_.notify_one();
      writer_.join();
      if (!failure_.empty()) spdlog::error("{}: the log {} is incomplete: {}", task_, path_, failure_);
    }
    if (file_ != nullptr) {
      (void)std::fclose(file_);
      file_ = nullptr;
    }
  }

  StringList names_;
  std::vector<In<double>> inputs_;
  std::unique_ptr<RowRing> ring_;
  const CycleTiming* timing_ = nullptr;
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<bool> writer_gone_{false};

  // The writer's side.
  std::string task_;
  std::string path_;
  std::FILE* file_ = nullptr;
  std::string out_;
  std::string failure_;
  // What could not be written (the writer's alone until it is joined, then kill's).
  bool writing_ = false;  // the run is on: a failure is said at once
  bool write_failed_ = false;
  std::string write_error_;
  std::uint64_t lost_rows_ = 0;
  std::size_t rows_in_out_ = 0;  // rows formatted since the last successful write
  double chunk_first_t_ = 0;     // t of the first of them
  double first_lost_t_ = 0;
  std::thread writer_;
  std::mutex mutex_;  // guards stop_ and wake_, never taken by a real-time cycle
  std::condition_variable wake_cv_;
  bool stop_ = false;
  bool wake_ = false;
};

}  // namespace

CHIMERA_REGISTER_MODULE(DataLogger);

}  // namespace chimera::modules
