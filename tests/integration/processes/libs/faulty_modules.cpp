// Modules that end or hang their process the ways a faulty module does (issue 15): a write through
// a null pointer, abort(), exit(3), and an endless loop in cycle() or on(); and some to be run in
// module processes beside others: one that asks for switches, one woken by a variable's updates,
// and a producer and consumer that tell whether the same-rate rule held between them. Each publishes a counter (so it
// is a writer of the table like any other) and ends its process at cycle `after`; with `once_file` set, only while that
// file does not exist (it creates it first), so that a restarted process runs on.

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <chimera/module/registry.hpp>

namespace {

enum class Fault { kSegfault, kAbort, kExit, kLoop };

template <Fault kFault>
class EndsItsProcess : public chimera::Module {
 public:
  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.out_var("faulty_count", chimera::Dim::fixed(1), "cycles run");
    d.param("after", 20.0, "", "the cycle that ends the process");
    d.param("once_file", std::string(), "", "end the process only while this file does not exist");
  }

 protected:
  chimera::Status init(chimera::InitContext& ctx) override {
    count_ = ctx.out<double>("faulty_count");
    after_ = static_cast<long>(ctx.params().number("after", 20.0));
    once_file_ = ctx.params().text("once_file", "");
    return chimera::Status::ok();
  }

  chimera::Status cycle() override {
    count_[0] = static_cast<double>(++cycles_);
    if (cycles_ < after_) return chimera::Status::ok();
    if (!once_file_.empty()) {
      const int fd = ::open(once_file_.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0600);
      if (fd < 0) return chimera::Status::ok();  // ended its process once already
      ::close(fd);
    }
    if constexpr (kFault == Fault::kAbort) {
      std::abort();
    } else if constexpr (kFault == Fault::kExit) {
      std::exit(3);
    } else if constexpr (kFault == Fault::kLoop) {
      for (;;) ::usleep(1000);  // endless, yet it leaves the CPU to the others: a module stuck, not a CPU hog
    } else {
      volatile int* nowhere = nullptr;
      *nowhere = 1;  // NOLINT(clang-analyzer-core.NullDereference): the fault under test
    }
    return chimera::Status::ok();
  }

 private:
  chimera::Out<double> count_;
  long after_ = 20;
  long cycles_ = 0;
  std::string once_file_;
};

class SegfaultInCycle final : public EndsItsProcess<Fault::kSegfault> {
 public:
  static constexpr const char* kName = "segfault_in_cycle";
  static constexpr const char* kSummary = "writes through a null pointer in cycle() (a test of module processes)";
  static constexpr const char* kDoc = "Ends its process with SIGSEGV at cycle `after`.";
};

class AbortInCycle final : public EndsItsProcess<Fault::kAbort> {
 public:
  static constexpr const char* kName = "abort_in_cycle";
  static constexpr const char* kSummary = "calls abort() in cycle() (a test of module processes)";
  static constexpr const char* kDoc = "Ends its process with SIGABRT at cycle `after`.";
};

class ExitInCycle final : public EndsItsProcess<Fault::kExit> {
 public:
  static constexpr const char* kName = "exit_in_cycle";
  static constexpr const char* kSummary = "calls exit(3) in cycle() (a test of module processes)";
  static constexpr const char* kDoc = "Ends its process with exit code 3 at cycle `after`.";
};

class LoopInCycle final : public EndsItsProcess<Fault::kLoop> {
 public:
  static constexpr const char* kName = "loop_in_cycle";
  static constexpr const char* kSummary = "never returns from cycle() (a test of module processes)";
  static constexpr const char* kDoc = "Stays in cycle() forever from cycle `after` on.";
};

// Stuck in on(): a module whose activation never returns (a wait on hardware that never answers).
class LoopInOn final : public chimera::Module {
 public:
  static constexpr const char* kName = "loop_in_on";
  static constexpr const char* kSummary = "never returns from on() (a test of the stuck-task watch)";
  static constexpr const char* kDoc = "Stays in on() forever; cycles do nothing.";
  static void declare(chimera::Declarations& /*d*/, const chimera::Params& /*params*/) {}

 protected:
  chimera::Status on() override {
    for (;;) ::usleep(1000);  // endless, yet it leaves the CPU to the others
  }
};

// Not faulty: asks for a switch to `to` from its cycle `after` on, every cycle (asking again
// while the request is pending costs nothing); a module process's way of reaching the subsystem
// interface, as a singularity monitor's.
class AsksForSwitch final : public chimera::Module {
 public:
  static constexpr const char* kName = "asks_for_switch";
  static constexpr const char* kSummary = "asks for a switch after some cycles (a test of module processes)";
  static constexpr const char* kDoc = "Asks for configuration `to` from cycle `after` on.";
  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.param("to", std::string(), "", "the configuration to ask for");
    d.param("after", 10.0, "", "the cycle from which it asks");
  }

 protected:
  chimera::Status init(chimera::InitContext& ctx) override {
    to_ = ctx.switch_request(ctx.params().text("to", ""));
    after_ = static_cast<long>(ctx.params().number("after", 10.0));
    return chimera::Status::ok();
  }
  chimera::Status on() override {
    cycles_ = 0;  // counts from each turning on
    return chimera::Status::ok();
  }
  chimera::Status cycle() override {
    if (++cycles_ >= after_) to_.ask();
    return chimera::Status::ok();
  }

 private:
  chimera::SwitchRequest to_;
  long after_ = 10;
  long cycles_ = 0;
};

// Not faulty: aperiodic, one cycle for each new value of its in-var `x` (trigger_on_update), which
// it counts into `updates`; to be woken across processes.
class CountsUpdates final : public chimera::Module {
 public:
  static constexpr const char* kName = "counts_updates";
  static constexpr const char* kSummary = "counts the updates of x that woke it (a test of module processes)";
  static constexpr const char* kDoc = "Aperiodic: a cycle for each new value of `x`; `updates` counts them.";
  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.in_var("x", chimera::Dim::fixed(1), "the variable whose updates wake it");
    d.out_var("updates", chimera::Dim::fixed(1), "cycles run");
  }

 protected:
  chimera::Status init(chimera::InitContext& ctx) override {
    x_ = ctx.in<double>("x");
    updates_ = ctx.out<double>("updates");
    ctx.trigger_on_update("x");
    return chimera::Status::ok();
  }
  chimera::Status cycle() override {
    updates_[0] += 1.0;
    return chimera::Status::ok();
  }

 private:
  chimera::In<double> x_;
  chimera::Out<double> updates_;
};

// Not faulty: a producer that writes its release (ns since start) as `stamp`, and a consumer of the
// same period that counts the releases whose stamp is not its own (`stamp_mismatches`): with the
// same-rate rule the consumer reads its producer's value of the same release, in any process.
class ReleaseStamp final : public chimera::Module {
 public:
  static constexpr const char* kName = "release_stamp";
  static constexpr const char* kSummary = "writes its release as stamp (a test of the same-rate rule)";
  static constexpr const char* kDoc = "Each cycle: stamp = its release, ns since start.";
  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.out_var("stamp", chimera::Dim::fixed(1), "the release of the cycle that wrote it, ns");
  }

 protected:
  chimera::Status init(chimera::InitContext& ctx) override {
    stamp_ = ctx.out<double>("stamp");
    timing_ = &ctx.timing();
    return chimera::Status::ok();
  }
  chimera::Status cycle() override {
    stamp_[0] = static_cast<double>(timing_->release_ns);
    return chimera::Status::ok();
  }

 private:
  chimera::Out<double> stamp_;
  const chimera::CycleTiming* timing_ = nullptr;
};

class ChecksStamp final : public chimera::Module {
 public:
  static constexpr const char* kName = "checks_stamp";
  static constexpr const char* kSummary = "counts stamps not of its own release (a test of the same-rate rule)";
  static constexpr const char* kDoc = "Each cycle: stamp_mismatches += 1 unless stamp is its own release.";
  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.in_var("stamp", chimera::Dim::fixed(1), "a producer's release, ns");
    d.out_var("stamp_mismatches", chimera::Dim::fixed(1), "releases that read another release's stamp");
  }

 protected:
  chimera::Status init(chimera::InitContext& ctx) override {
    stamp_ = ctx.in<double>("stamp");
    mismatches_ = ctx.out<double>("stamp_mismatches");
    timing_ = &ctx.timing();
    return chimera::Status::ok();
  }
  chimera::Status cycle() override {
    if (stamp_[0] != static_cast<double>(timing_->release_ns)) mismatches_[0] += 1.0;
    return chimera::Status::ok();
  }

 private:
  chimera::In<double> stamp_;
  chimera::Out<double> mismatches_;
  const chimera::CycleTiming* timing_ = nullptr;
};

// A stray pointer: at its cycle `after` it writes into every page of its process's mapping of the
// subsystem's table, the last page first, each byte written as it was read. In a module process
// only its own variable's pages (and the header's) take a write: the first other page ends the
// process with SIGSEGV. Its out-var counts the pages written.
class ScribblesOnTheTable final : public chimera::Module {
 public:
  static constexpr const char* kName = "scribbles_on_the_table";
  static constexpr const char* kSummary = "writes over the whole state variable table (a test of module processes)";
  static constexpr const char* kDoc = "At cycle `after`, writes into every page of its mapping of the table.";
  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.out_var("pages_scribbled", chimera::Dim::fixed(1), "pages of the table it wrote into");
    d.param("after", 20.0, "", "the cycle that scribbles");
  }

 protected:
  chimera::Status init(chimera::InitContext& ctx) override {
    pages_ = ctx.out<double>("pages_scribbled");
    after_ = static_cast<long>(ctx.params().number("after", 20.0));
    return chimera::Status::ok();
  }
  chimera::Status cycle() override {
    if (++cycles_ != after_) return chimera::Status::ok();
    // The table's mapping, found as a stray pointer would find it: by what it is named.
    std::FILE* maps = std::fopen("/proc/self/maps", "r");
    if (maps == nullptr) return chimera::Status::fail("no /proc/self/maps");
    std::array<char, 512> line{};
    std::uintptr_t begin = 0;
    std::uintptr_t end = 0;
    while (std::fgets(line.data(), static_cast<int>(line.size()), maps) != nullptr)
      if (std::strstr(line.data(), "/dev/shm/chimera_") != nullptr)
        (void)std::sscanf(line.data(), "%lx-%lx", &begin, &end);  // NOLINT(cert-err34-c): a test's parse
    std::fclose(maps);
    if (begin == 0) return chimera::Status::fail("no table mapped");
    const std::uintptr_t page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    for (std::uintptr_t at = end - page; at >= begin; at -= page) {
      // NOLINTNEXTLINE(performance-no-int-to-ptr): the stray pointer under test
      volatile char* p = reinterpret_cast<char*>(at);
      *p = *p;
      pages_[0] += 1.0;
      if (at == begin) break;
    }
    return chimera::Status::ok();
  }

 private:
  chimera::Out<double> pages_;
  long after_ = 20;
  long cycles_ = 0;
};

}  // namespace

CHIMERA_REGISTER_MODULE(SegfaultInCycle);
CHIMERA_REGISTER_MODULE(AbortInCycle);
CHIMERA_REGISTER_MODULE(ExitInCycle);
CHIMERA_REGISTER_MODULE(LoopInCycle);
CHIMERA_REGISTER_MODULE(LoopInOn);
CHIMERA_REGISTER_MODULE(AsksForSwitch);
CHIMERA_REGISTER_MODULE(CountsUpdates);
CHIMERA_REGISTER_MODULE(ReleaseStamp);
CHIMERA_REGISTER_MODULE(ChecksStamp);
CHIMERA_REGISTER_MODULE(ScribblesOnTheTable);
