// `chimera run` against the machine's resources, each the real thing: a /dev/shm with no room
// left (a small tmpfs mounted over it in a mount namespace of the test's own), a log on /dev/full
// and on a disk that fills during the run, shared memory left by a run killed with SIGKILL
// (its pid dead, or its pid now a live unrelated process's), two live runs of one name, every
// sequence of SIGINT, SIGTERM and SIGHUP sent to a running process, and the CPUs its ordinary
// threads may use beside its real-time ones; `chimera analyze`'s measuring runs stopped by a
// signal or killed outright.

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "chimera/svt/detail/shm_layout.hpp"
#include "run_chimera.hpp"
#include "support/json_text.hpp"

namespace chimera::test {
namespace {

using namespace std::chrono_literals;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A subsystem of built-in modules whose table is a few kilobytes, with a data logger. Every task
// is soft: a real-clock run on a loaded machine may miss deadlines, which must not end it.
// The log's parameters are on line 10, its task at line 6; `more` adds to them.
std::string subsystem_file(const std::string& name, const std::string& log_file, const std::string& more = {}) {
  return "subsystem: " + name +
         "\n"
         "tasks:\n"
         "  - { name: traj, module: joint_traj_gen, period: 1ms, criticality: soft }\n"
         "  - { name: pid, module: pid_joint, period: 1ms, criticality: soft }\n"
         "  - { name: robot, module: robot_torque, period: 1ms, criticality: soft }\n"
         "  - name: log\n"
         "    module: data_logger\n"
         "    period: 1ms\n"
         "    criticality: soft\n"
         "    params: { variables: [theta_d, theta_m, dtheta_m, tau_r], file: " +
         log_file + more + " }\n";
}

// Runs a shell script in a mount namespace of its own (as root, or as a user mapped to root where
// user namespaces are allowed): what it mounts vanishes with it, and the machine's /dev/shm is
// never touched. Captures what it prints.
Outcome in_own_mount_namespace(const TempDir& dir, const std::string& script) {
  const std::string out = dir.file("ns_stdout.txt");
  const std::string err = dir.file("ns_stderr.txt");
  const std::string command = std::string(::geteuid() == 0 ? "unshare --mount" : "unshare --mount --map-root-user") +
                              " sh -c " + quoted(script) + " </dev/null >" + quoted(out) + " 2>" + quoted(err);
  const int status = std::system(command.c_str());  // NOLINT(concurrency-mt-unsafe): tests run one thread
  Outcome o;
  o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = read_text(out);
  o.err = read_text(err);
  return o;
}

/// A `chimera run` process of the test's own, for signals: stdin at its end, so that on the
/// real clock without --for only a signal ends it.
class RunningChimera {
 public:
  RunningChimera(const TempDir& dir, const std::vector<std::string>& args) : out_(dir.file("run_out.txt")) {
    pid_ = ::fork();
    if (pid_ == 0) {
      ::setenv("CHIMERA_LOG_DIR", dir.path().c_str(), 1);  // NOLINT(concurrency-mt-unsafe): the child has one thread
      const int null = ::open("/dev/null", O_RDONLY);
      const int out = ::open(out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
      ::dup2(null, STDIN_FILENO);
      ::dup2(out, STDOUT_FILENO);
      ::dup2(out, STDERR_FILENO);
      std::vector<char*> argv{
          const_cast<char*>(CHIMERA_BIN)};  // NOLINT(cppcoreguidelines-pro-type-const-cast): execv's type
      for (const auto& a : args)
        argv.push_back(const_cast<char*>(a.c_str()));  // NOLINT(cppcoreguidelines-pro-type-const-cast): as above
      argv.push_back(nullptr);
      ::execv(CHIMERA_BIN, argv.data());
      ::_exit(127);
    }
  }
  ~RunningChimera() {
    if (pid_ > 0 && !reaped_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  RunningChimera(const RunningChimera&) = delete;
  RunningChimera& operator=(const RunningChimera&) = delete;

  [[nodiscard]] pid_t pid() const { return pid_; }
  void signal(int signo) const { ::kill(pid_, signo); }
  /// The wait status once it has ended, or -1 if it has not within `limit`.
  int wait(std::chrono::seconds limit) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        reaped_ = true;
        return status;
      }
      std::this_thread::sleep_for(10ms);
    }
    return -1;
  }
  [[nodiscard]] std::string output() const { return read_text(out_); }

 private:
  std::string out_;
  pid_t pid_ = -1;
  bool reaped_ = false;
};

std::string region_path(const std::string& name) { return "/dev/shm/chimera_" + name; }

// Waits for a run's shared memory to appear: the run has started.
bool wait_for_region(const std::string& name) {
  for (int i = 0; i < 3000; ++i) {
    if (std::filesystem::exists(region_path(name))) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

class ResourcesCliTest : public ::testing::Test {
 protected:
  std::string name(const std::string& what) {
    return "res_" + what + "_" + std::to_string(::getpid()) + "_" + std::to_string(count_++);
  }
  std::string file(const std::string& subsystem, const std::string& log_file = "log.csv",
                   const std::string& more = {}) {
    const std::string path = dir_.file(subsystem + ".yaml");
    write_text(path, subsystem_file(subsystem, log_file, more));
    return path;
  }
  Outcome chimera(const std::string& args, const std::string& prefix = {}) {
    return run_chimera(dir_, args, {}, "CHIMERA_LOG_DIR=" + quoted(dir_.path()) + " " + prefix);
  }
  void TearDown() override {
    for (const auto& n : names_) std::filesystem::remove(region_path(n));
  }
  std::string tracked(const std::string& n) {
    names_.push_back(n);
    return n;
  }

  TempDir dir_;
  int count_ = 0;
  std::vector<std::string> names_;
};

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

TEST_F(ResourcesCliTest, AFullDevShmIsOneMessageAndExit2NeverSigbus) {
  const std::string n = name("full");
  const std::string f = file(n);
  // A /dev/shm of 256 KiB, filled to the last block by another file before chimera starts.
  const std::string script =
      "mount -t tmpfs -o size=256k tmpfs /dev/shm && "
      "(dd if=/dev/zero of=/dev/shm/filler bs=4k 2>/dev/null; true) && "
      "exec " +
      quoted(CHIMERA_BIN) + " run " + quoted(f) + " --clock virtual --for 100ms";
  const auto o = in_own_mount_namespace(dir_, script);
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "no room in /dev/shm for the state variable table of subsystem '" + n + "': it needs "))
      << o.err;
  EXPECT_TRUE(contains(o.err, " bytes, 0 are free (shared memory /chimera_" + n + ")")) << o.err;
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line: " << o.err;
  EXPECT_EQ(o.out, "");
}

TEST_F(ResourcesCliTest, ALogOnDevFullIsRefusedBeforeTheRunStarts) {
  const std::string n = tracked(name("devfull"));
  const std::string f = file(n, "/dev/full");
  const auto o = chimera("run " + quoted(f) + " --clock virtual --for 100ms");
  EXPECT_EXIT_CODE(o, 2);
  // At the line of the parameter init refused, as the loader's messages are.
  EXPECT_TRUE(
      contains(o.err, f + ":10: log.params.file: init failed: cannot write the log /dev/full: No space left on device"))
      << o.err;
  EXPECT_FALSE(std::filesystem::exists(region_path(n)));
}

// `capacity` counts rows, the variables set their width: a ring past 1 GiB is refused at the
// parameter's line, by run and by analyze's measuring run alike, never a bad_alloc.
TEST_F(ResourcesCliTest, ALoggerRingPastItsMemoryBoundIsRefusedAtItsLineByRunAndAnalyze) {
  const std::string n = tracked(name("bigring"));
  const std::string f = file(n, "log.csv", ", capacity: 1e8");
  const std::string said = f +
                           ":10: log.params.capacity: init failed: 100000000 rows of 25 values take 19073 MiB, "
                           "past the ring's 1024 MiB: at most 5368709 rows";
  const auto run = chimera("run " + quoted(f) + " --clock virtual --for 100ms");
  EXPECT_EXIT_CODE(run, 2);
  EXPECT_TRUE(contains(run.err, said)) << run.err;
  const auto analyze = chimera("analyze " + quoted(f));
  EXPECT_EXIT_CODE(analyze, 2);
  EXPECT_TRUE(analyze.err.starts_with(said)) << analyze.err;
  EXPECT_FALSE(std::filesystem::exists(region_path(n)));
}

// A writer that falls behind loses rows as surely as a full disk: the run must not end as if
// its log were whole. A ring of 16 rows at 1 kHz, drained every 20 ms, cannot keep up.
TEST_F(ResourcesCliTest, ALoggerWhoseRingOverflowsOnTheRealClockEndsTheRunWith1AndTheCount) {
  const std::string n = tracked(name("overflow"));
  const auto o = chimera("run " + quoted(file(n, "log.csv", ", capacity: 16")) + " --clock real --for 500ms");
  EXPECT_EXIT_CODE(o, 1);
  ASSERT_FALSE(o.err.empty());
  const std::string last = o.err.substr(o.err.rfind('\n', o.err.size() - 2) + 1);
  EXPECT_TRUE(last.starts_with("chimera: exit 1: task log: kill failed: ")) << o.err;
  EXPECT_TRUE(contains(last, " rows lost: not logged to " + dir_.file("log.csv") +
                                 ", the ring of 16 rows was full (the writer fell behind: raise capacity)"))
      << last;
  EXPECT_FALSE(std::filesystem::exists(region_path(n)));
}

TEST_F(ResourcesCliTest, ALogWhoseDiskFillsDuringTheRunSaysSoCountsItsLostRowsAndTheRunExits1) {
  const std::string n = name("diskfull");
  const std::string logs = dir_.file("small_disk");
  std::filesystem::create_directories(logs);
  const std::string json = dir_.file("stats.json");
  const std::string lines = dir_.file("lines.txt");
  // 2 s of rows of 25 numbers (about 500 KB) onto a disk of 64 KiB.
  const std::string script = "mount -t tmpfs -o size=64k tmpfs " + quoted(logs) +
                             " && CHIMERA_LOG_DIR=" + quoted(logs) + " " + quoted(CHIMERA_BIN) + " run " +
                             quoted(file(n)) + " --clock virtual --for 2s --stats-json " + quoted(json) +
                             "; code=$?; wc -l < " + quoted(logs + "/log.csv") + " > " + quoted(lines) + "; exit $code";
  const auto o = in_own_mount_namespace(dir_, script);
  EXPECT_EXIT_CODE(o, 1);
  // Said once, as it happened, naming the file and why.
  const std::string said =
      "log: cannot write the log " + logs + "/log.csv: No space left on device; its rows from t = ";
  EXPECT_TRUE(contains(o.err, said)) << o.err;
  EXPECT_EQ(o.err.find(said), o.err.rfind(said)) << o.err;
  // The run's last line says why it exits 1, with the count.
  ASSERT_FALSE(o.err.empty());
  const std::string last = o.err.substr(o.err.rfind('\n', o.err.size() - 2) + 1);
  EXPECT_TRUE(last.starts_with("chimera: exit 1: task log: kill failed: ")) << o.err;
  EXPECT_TRUE(contains(last, " rows lost: the log " + logs + "/log.csv could not be written from t = ")) << last;
  EXPECT_TRUE(contains(last, " s on: No space left on device (task destroyed)\n")) << last;
  const std::size_t count_at = last.find("kill failed: ") + std::string("kill failed: ").size();
  const std::uint64_t lost = std::stoull(last.substr(count_at));
  // Every row the task took is either in the file or counted lost (a cut last chunk counts lost).
  const auto cycles = test::parse_json(read_text(json)).at("tasks").at("log").at("cycles").get<std::uint64_t>();
  const std::uint64_t written = std::stoull(read_text(lines)) - 1;  // less the header
  EXPECT_GT(lost, 0U);
  EXPECT_LE(lost, cycles);
  EXPECT_GE(written + lost, cycles) << written << " written, " << lost << " lost, " << cycles << " cycles";
  // The timing table still came out, and nothing was left in /dev/shm.
  EXPECT_TRUE(contains(o.out, "latency p99")) << o.out;
  EXPECT_FALSE(std::filesystem::exists(region_path(n)));
}

// On the real clock the tasks run on while the run ends. The figures of --stats-json are
// those of the tasks stopped, so that every cycle the logger ran has its row, and the other way
// round (the hour's soak found one row more than the cycles, when the figures were taken a moment
// before the tasks stopped).
TEST_F(ResourcesCliTest, ARealClockRunsFiguresCountEveryRowItsLoggerWrote) {
  const std::string n = tracked(name("rows"));
  const std::string json = dir_.file("stats.json");
  const auto o = chimera("run " + quoted(file(n)) + " --clock real --for 1500ms --stats-json " + quoted(json));
  EXPECT_EXIT_CODE(o, 0);
  const auto log = test::parse_json(read_text(json)).at("tasks").at("log");
  EXPECT_EQ(log.at("state"), "ON");  // the state while it ran, not NOT-CREATED
  const auto cycles = log.at("cycles").get<std::uint64_t>();
  EXPECT_GT(cycles, 500U);
  // A ring that filled (the writer thread starved for a second) would say how many rows it
  // dropped: then this comparison would not hold, and the message says why.
  const std::string rows = read_text(dir_.file("log.csv"));
  const auto lines = static_cast<std::uint64_t>(std::count(rows.begin(), rows.end(), '\n'));
  ASSERT_GE(lines, 1U);
  EXPECT_EQ(lines - 1, cycles) << o.err;  // less the header
}

TEST_F(ResourcesCliTest, TheRegionOfARunKilledWithSigkillIsReclaimedWhateverBecameOfItsPid) {
  // The real leftover: a run killed the one way no handler sees.
  const std::string n = tracked(name("killed"));
  const std::string f = file(n);
  // What the stale region's pid is by the time the next run looks: still dead, a live unrelated
  // process (this test's), the init process (always alive).
  for (const pid_t recorded : {pid_t{0}, ::getpid(), pid_t{1}}) {
    {
      RunningChimera run(dir_, {"run", f});
      ASSERT_TRUE(wait_for_region(n)) << run.output();
      run.signal(SIGKILL);
      ASSERT_NE(run.wait(30s), -1);
    }
    ASSERT_TRUE(std::filesystem::exists(region_path(n))) << "SIGKILL leaves the region behind";
    if (recorded != 0) {
      const int fd = ::open(region_path(n).c_str(), O_RDWR);
      ASSERT_GE(fd, 0);
      void* p = ::mmap(nullptr, sizeof(svt_detail::Header), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
      ASSERT_NE(p, MAP_FAILED);
      const auto pid = static_cast<std::uint64_t>(recorded);
      std::memcpy(static_cast<std::byte*>(p) + offsetof(svt_detail::Header, owner_pid), &pid, sizeof(pid));
      ::munmap(p, sizeof(svt_detail::Header));
      ::close(fd);
    }
    const auto o = chimera("run " + quoted(f) + " --clock virtual --for 50ms");
    EXPECT_EXIT_CODE(o, 0) << " (pid recorded: " << recorded << ")";
    EXPECT_FALSE(std::filesystem::exists(region_path(n)));
  }
}

TEST_F(ResourcesCliTest, TwoLiveRunsOfOneNameRefuseEachOther) {
  const std::string n = tracked(name("twice"));
  const std::string f = file(n);
  RunningChimera first(dir_, {"run", f});
  ASSERT_TRUE(wait_for_region(n)) << first.output();
  const auto second = chimera("run " + quoted(f) + " --clock virtual --for 50ms");
  EXPECT_EXIT_CODE(second, 2);
  EXPECT_TRUE(contains(second.err, "subsystem '" + n + "' is already running (pid " + std::to_string(first.pid()) +
                                       "); shared memory /chimera_" + n))
      << second.err;
  // The refused run left the first one's region alone; the first stops cleanly and removes it.
  EXPECT_TRUE(std::filesystem::exists(region_path(n)));
  first.signal(SIGTERM);
  const int status = first.wait(30s);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status << "\n" << first.output();
  EXPECT_FALSE(std::filesystem::exists(region_path(n)));
}

TEST_F(ResourcesCliTest, NoSequenceOfStopSignalsLeavesTheRegionBehind) {
  const std::vector<std::vector<int>> sequences{
      {SIGINT},
      {SIGTERM},
      {SIGHUP},
      {SIGTERM, SIGTERM},
      {SIGINT, SIGINT},
      {SIGHUP, SIGHUP},
      {SIGINT, SIGTERM},
      {SIGTERM, SIGHUP},
      {SIGHUP, SIGINT, SIGTERM},
      {SIGTERM, SIGTERM, SIGTERM, SIGTERM},
  };
  // Sent in a row as fast as they can be (the kernel may merge two of one kind), and 2 ms apart,
  // so that the later ones arrive while the first one's stop is under way.
  for (const auto gap : {0ms, 2ms})
    for (const auto& sequence : sequences) {
      std::string said = std::to_string(gap.count()) + " ms apart: ";
      for (const int s : sequence) said += std::string(sigabbrev_np(s)) + " ";
      const std::string n = tracked(name("signals"));
      RunningChimera run(dir_, {"run", file(n)});
      ASSERT_TRUE(wait_for_region(n)) << run.output();
      const auto first_sent = std::chrono::steady_clock::now();
      for (const int s : sequence) {
        run.signal(s);
        std::this_thread::sleep_for(gap);
      }
      const auto sending = std::chrono::steady_clock::now() - first_sent;
      const int status = run.wait(60s);
      ASSERT_NE(status, -1) << said << "did not end";
      EXPECT_FALSE(std::filesystem::exists(region_path(n))) << said << "left " << region_path(n);
      // This test's subject, above, holds whatever the timing. What follows needs the signals to
      // have gone within the grace: a machine that held this thread up for most of a second (a
      // SCHED_FIFO test beside it on both CPUs) made the last one a second request, rightly.
      if (sending > 500ms) continue;
      // Signals within a second of the first are one request (timeout(1) itself sends two): the
      // clean stop, with its timing table. A later one would end a stuck stop at once, its shared
      // memory removed first (GlobalTable.TheSignalTimeRemovalTakesOnlyThisProcesssOwnNames).
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << said << status << "\n" << run.output();
      EXPECT_TRUE(contains(run.output(), "latency p99")) << said << run.output();
    }
}

// A thread of a running process: its name, its scheduling policy and the CPUs it may run on.
struct ThreadPlace {
  std::string name;
  int policy = -1;
  std::vector<int> cpus;
};

std::vector<int> cpus_of(const cpu_set_t& set) {
  std::vector<int> cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &set)) cpus.push_back(cpu);
  return cpus;
}

std::vector<ThreadPlace> threads_of(pid_t pid) {
  std::vector<ThreadPlace> out;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task", ec)) {
    const auto tid = static_cast<pid_t>(std::stol(entry.path().filename().string()));
    cpu_set_t set;
    CPU_ZERO(&set);
    if (::sched_getaffinity(tid, sizeof(set), &set) != 0) continue;  // ended meanwhile
    std::string name = read_text(entry.path().string() + "/comm");
    if (!name.empty() && name.back() == '\n') name.pop_back();
    out.push_back({name, ::sched_getscheduler(tid), cpus_of(set)});
  }
  return out;
}

// The ordinary threads (the network API's among them, started after the tasks) keep off the CPUs
// of the real-time tasks where a CPU has none: on this kernel a thread inside a system call is not
// preempted, so a task released meanwhile would wait for it. Where every CPU has a task, or
// SCHED_FIFO is refused, they keep every CPU the process may use.
TEST_F(ResourcesCliTest, OrdinaryThreadsKeepOffTheCpusOfTheRealTimeTasks) {
  const std::string n = tracked(name("ordinary"));
  RunningChimera run(dir_, {"run", file(n), "--listen", "127.0.0.1:0"});
  ASSERT_TRUE(wait_for_region(n)) << run.output();
  std::vector<ThreadPlace> threads;
  for (int i = 0; i < 1000; ++i) {  // the server's threads start after the region appears
    threads = threads_of(run.pid());
    if (std::any_of(threads.begin(), threads.end(), [](const auto& t) { return t.name == "civetweb-master"; })) break;
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(std::any_of(threads.begin(), threads.end(), [](const auto& t) { return t.name == "civetweb-master"; }))
      << run.output();
  cpu_set_t usable_set;
  CPU_ZERO(&usable_set);
  ASSERT_EQ(::sched_getaffinity(0, sizeof(usable_set), &usable_set), 0);
  const std::vector<int> usable = cpus_of(usable_set);
  std::vector<int> realtime;  // the CPUs the real-time threads are pinned to
  for (const auto& t : threads)
    if (t.policy == SCHED_FIFO) {
      EXPECT_EQ(t.cpus.size(), 1U) << t.name << ": a real-time thread is pinned to its CPU";
      realtime.insert(realtime.end(), t.cpus.begin(), t.cpus.end());
    }
  std::vector<int> expected;
  for (const int cpu : usable)
    if (std::find(realtime.begin(), realtime.end(), cpu) == realtime.end()) expected.push_back(cpu);
  if (realtime.empty() || expected.empty()) expected = usable;
  int ordinary = 0;
  for (const auto& t : threads)
    if (t.policy != SCHED_FIFO) {
      ++ordinary;
      EXPECT_EQ(t.cpus, expected) << t.name << " (" << realtime.size() << " real-time threads)";
    }
  EXPECT_GT(ordinary, 3) << "the main thread, the service thread and the server's";
  run.signal(SIGTERM);
  const int status = run.wait(30s);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status << "\n" << run.output();
}

// A file whose measuring runs take seconds: 200 tasks at 100 us, two million releases a run.
std::string slow_to_measure(const std::string& name) {
  std::string yaml = "subsystem: " + name + "\ntasks:\n";
  for (int i = 0; i < 200; ++i)
    yaml += "  - { name: t" + std::to_string(i) + ", module: cpu_load, period: 100us, criticality: soft }\n";
  return yaml;
}

// The shared memory of `name`'s measuring runs (chimera_NAME_measure_PID_N).
std::vector<std::string> measure_regions(const std::string& name) {
  std::vector<std::string> found;
  const std::string prefix = "chimera_" + name + "_measure_";
  for (const auto& e : std::filesystem::directory_iterator("/dev/shm"))
    if (e.path().filename().string().starts_with(prefix)) found.push_back(e.path().string());
  return found;
}

bool wait_for_measure_region(const std::string& name) {
  for (int i = 0; i < 3000; ++i) {
    if (!measure_regions(name).empty()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

TEST_F(ResourcesCliTest, AnalyzeStoppedByASignalWhileMeasuringExits2AndLeavesNoRegion) {
  const std::string n = name("measure_term");
  const std::string f = dir_.file(n + ".yaml");
  write_text(f, slow_to_measure(n));
  RunningChimera run(dir_, {"analyze", f});
  ASSERT_TRUE(wait_for_measure_region(n)) << run.output();
  run.signal(SIGTERM);
  const int status = run.wait(60s);
  ASSERT_NE(status, -1) << "analyze did not end";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << status << "\n" << run.output();
  EXPECT_TRUE(contains(run.output(), "stopped by a signal while measuring")) << run.output();
  EXPECT_TRUE(measure_regions(n).empty()) << measure_regions(n).front();
}

TEST_F(ResourcesCliTest, TheRegionOfAnAnalyzeKilledOutrightIsRemovedByTheNextAnalyze) {
  const std::string n = name("measure_kill");
  const std::string f = dir_.file(n + ".yaml");
  write_text(f, slow_to_measure(n));
  {
    RunningChimera run(dir_, {"analyze", f});
    ASSERT_TRUE(wait_for_measure_region(n)) << run.output();
    run.signal(SIGKILL);
    ASSERT_NE(run.wait(30s), -1);
  }
  const auto left = measure_regions(n);
  ASSERT_EQ(left.size(), 1u) << "SIGKILL leaves the measuring run's region behind";
  for (const auto& path : left) names_.push_back(path.substr(std::string("/dev/shm/chimera_").size()));
  // The next analyze of that subsystem, a quick one, removes it (its pid is in its name, so no
  // run of that name would ever be made again).
  write_text(f, "subsystem: " + n + "\ntasks:\n  - { name: t, module: cpu_load, period: 1ms, criticality: soft }\n");
  const auto o = chimera("analyze " + quoted(f));
  EXPECT_EXIT_CODE(o, 0) << o.err;
  EXPECT_TRUE(contains(o.err, "removed 1 shared memory region left by an earlier chimera analyze")) << o.err;
  EXPECT_TRUE(measure_regions(n).empty());
}

}  // namespace
}  // namespace chimera::test
