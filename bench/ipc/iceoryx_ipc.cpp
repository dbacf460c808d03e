// The latest value from one process to another through iceoryx 2.0 (Debian's package): zero-copy
// shared memory brokered by the RouDi daemon, which this program starts and stops itself. The
// subscriber keeps one sample (queue capacity 1, the oldest discarded), the latest-value
// semantics of a state variable. Keys: iceoryx_latency_ns_p50, iceoryx_latency_ns_p99.
//
//   iceoryx_ipc [--quick] [--out FILE] [--samples-dir DIR] [--roudi PATH]

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <string>

#include "iceoryx_hoofs/log/logmanager.hpp"
#include "iceoryx_posh/popo/publisher.hpp"
#include "iceoryx_posh/popo/subscriber.hpp"
#include "iceoryx_posh/runtime/posh_runtime.hpp"
#include "ipc/ipc_latency.hpp"

extern char** environ;  // NOLINT: POSIX

namespace chimera::bench {
namespace {

const iox::capro::ServiceDescription kService{"Chimera", "Bench", "LatestValue"};
constexpr const char* kWhat = "iceoryx 2.0.3 (Debian), RouDi, zero-copy shared memory, queue of 1";

struct IoxPub {
  iox::popo::Publisher<Message> publisher{kService};
  bool ready() { return publisher.hasSubscribers(); }
  void publish(const Message& m) {
    publisher.loan().and_then([&](auto& sample) {
      *sample = m;
      sample.publish();
    });
  }
};

iox::popo::SubscriberOptions latest_only() {
  iox::popo::SubscriberOptions o;
  o.queueCapacity = 1U;  // latest value: a new sample replaces an unread one
  o.queueFullPolicy = iox::popo::QueueFullPolicy::DISCARD_OLDEST_DATA;
  return o;
}

struct IoxSub {
  iox::popo::Subscriber<Message> subscriber{kService, latest_only()};
  bool take_latest(Message& m) {
    bool got = false;
    subscriber.take().and_then([&](auto& sample) {
      m = *sample;
      got = true;
    });
    return got;
  }
};

void init_runtime(const char* name) {
  iox::runtime::PoshRuntime::initRuntime(iox::RuntimeName_t(iox::cxx::TruncateToCapacity, name));
}

/// RouDi, the iceoryx daemon, for the duration of the benchmark.
class Roudi {
 public:
  Roudi(const std::string& path, const std::string& log) {
    std::string arg0 = path;
    std::string level = "--log-level";
    std::string warn = "warning";
    std::array<char*, 4> argv{arg0.data(), level.data(), warn.data(), nullptr};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    ok_ = posix_spawnp(&pid_, path.c_str(), &actions, nullptr, argv.data(), environ) == 0;
    posix_spawn_file_actions_destroy(&actions);
    if (!ok_) return;
    // RouDi is up once its management segment exists (the runtime would wait for it anyway);
    // one that exits at once found another RouDi running.
    struct stat st {};
    for (int i = 0; i < 500 && ::stat("/dev/shm/iceoryx_mgmt", &st) != 0; ++i) ::usleep(10'000);
    ::usleep(100'000);
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      ok_ = false;
      pid_ = -1;
    }
  }
  Roudi(const Roudi&) = delete;
  Roudi& operator=(const Roudi&) = delete;
  ~Roudi() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  [[nodiscard]] bool ok() const { return ok_; }

 private:
  pid_t pid_ = -1;
  bool ok_ = false;
};

}  // namespace
}  // namespace chimera::bench

int main(int argc, char** argv) {
  using namespace chimera::bench;
  Args args = Args::parse(argc, argv);
  std::string roudi_path = "iox-roudi";
  for (std::size_t i = 0; i + 1 < args.rest.size(); ++i)
    if (args.rest[i] == "--roudi") roudi_path = args.rest[i + 1];
  const IpcPlan plan = plan_for(args);
  const std::string log = args.samples_dir.empty() ? "/dev/null" : args.samples_dir + "/roudi.log";
  Roudi roudi(roudi_path, log);
  if (!roudi.ok()) {
    IpcRun failed;
    failed.error = "could not start RouDi (" + roudi_path + "), or another RouDi is running; see " + log;
    return report_ipc(args, "iceoryx", kWhat, failed, plan);
  }
  // Publisher and subscriber both run in children: each leaves RouDi (runtime destructor at
  // exit) before this process stops RouDi, which would otherwise signal them.
  std::fflush(nullptr);
  const pid_t measure = ::fork();
  if (measure == 0) {
    iox::log::LogManager::GetLogManager().SetDefaultLogLevel(iox::log::LogLevel::kWarn);
    IpcRun run = run_ipc_latency<IoxPub, IoxSub>(
        plan,
        [] {
          init_runtime("chimera-bench-pub");
          return std::make_unique<IoxPub>();
        },
        [] {
          init_runtime("chimera-bench-sub");
          return std::make_unique<IoxSub>();
        });
    std::exit(report_ipc(args, "iceoryx", kWhat, run, plan));
  }
  int status = 0;
  ::waitpid(measure, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}
