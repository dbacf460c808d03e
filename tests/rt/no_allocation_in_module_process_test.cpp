// The cross-process path allocates nothing (issue 15): a module process's body, the very function
// `chimera __worker` runs (run_module_process), run on a thread of this process so that the
// allocation guard sees it. Its tasks keep their states, statistics and events in a task block,
// read and write the global table another owner created, and record into the flight recorder's
// shared rings, as a worker's tasks do; this test plays the main process's part over the command
// socket.

#include <fcntl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "chimera/control/module_process_main.hpp"
#include "chimera/control/subsystem.hpp"
#include "control/flight_recorder.hpp"
#include "exec/process_protocol.hpp"
#include "exec/task_block.hpp"
#include "exec/task_set.hpp"
#include "support/allocation_guard.hpp"
#include "support/probe_module.hpp"

namespace chimera {
namespace {

using testing::AllocationGuard;

std::int64_t monotonic_now_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleep_ms(int ms) {
  timespec ts{ms / 1000, static_cast<long>(ms % 1000) * 1'000'000};
  while (::nanosleep(&ts, &ts) != 0) {
  }
}

Result<void> command(int socket_fd, const ProcessCommand& c) {
  if (::send(socket_fd, &c, sizeof c, MSG_NOSIGNAL) != static_cast<ssize_t>(sizeof c))
    return make_error(Errc::kSystem, "send");
  ProcessReply reply;
  if (::recv(socket_fd, &reply, sizeof reply, 0) != static_cast<ssize_t>(sizeof reply))
    return make_error(Errc::kSystem, "recv");
  return reply.result();
}

// The snapshot allocates: never called while the guard is armed.
std::uint64_t cycles_of(TaskBlock& block, std::size_t tasks) {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < tasks; ++i) n += block.slot(i)->stats.snapshot().cycles;
  return n;
}

TEST(NoAllocationInModuleProcess, Figure4InAWorkerOnTheRealClock) {
  auto spec = load_subsystem_file(CHIMERA_EXAMPLES_DIR "/fig4_pid_joint.yaml", Registry::global());
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  // The file with every task in one module process. Soft: a deadline a loaded machine makes them
  // miss must not end their cycling (ERROR); the subject here is allocation, not timing.
  SubsystemSpec in_worker = *spec;
  for (auto& t : in_worker.tasks) {
    t.process = "arm";
    t.criticality = Criticality::kSoft;
  }
  const std::size_t n = in_worker.tasks.size();
  // The table, its constants written and laid out a page apart as for module processes, made by a
  // subsystem that is never started: the owner the worker attaches to.
  RunOptions options;
  options.shm_suffix = testing::unique_suffix();
  options.realtime_priorities = false;
  auto owner = Subsystem::create(in_worker, Registry::global(), options);
  ASSERT_TRUE(owner.ok()) << owner.error().message;

  auto block = TaskBlock::create(n);
  ASSERT_TRUE(block.ok()) << block.error().message;
  block->set_epoch_ns(monotonic_now_ns());
  // The flight recorder's rings, shared, as the main process of a run with module processes makes
  // them: laid out from the same file over the same table (whose tasks here are never spawned).
  const Resolution resolution = resolve_subsystem(in_worker, Registry::global());
  auto table = GlobalTable::attach(spec->name + options.shm_suffix);
  ASSERT_TRUE(table.ok()) << table.error().message;
  TaskSet views(resolution.subsystem, *table, nullptr);
  auto recorder = FlightRecorder::create(resolution.subsystem, *table, views, 2.0, FlightRecorder::Memory::kShared);
  ASSERT_TRUE(recorder.ok()) << recorder.error().message;

  int sockets[2] = {-1, -1};
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sockets), 0);
  ModuleProcessArgs args;
  args.process = "arm";
  args.table = spec->name + options.shm_suffix;
  args.socket_fd = sockets[1];
  args.block_fd = block->fd();
  args.history_fd = ::fcntl((*recorder)->shared_fd(), F_DUPFD_CLOEXEC, 0);  // the worker keeps (and closes) its own
  args.record_seconds = (*recorder)->seconds();
  args.realtime_priorities = false;
  int exit_code = -1;
  std::thread worker([&] { exit_code = run_module_process(in_worker, Registry::global(), args); });

  ProcessReply ready;
  ASSERT_EQ(::recv(sockets[0], &ready, sizeof ready, 0), static_cast<ssize_t>(sizeof ready));
  ASSERT_TRUE(ready.result().ok()) << ready.result().error().message;
  ProcessCommand on;
  on.kind = ProcessCommandKind::kTurnOnTogether;
  for (std::size_t i = 0; i < n; ++i) {
    ProcessCommand spawn;
    spawn.kind = ProcessCommandKind::kSignal;
    spawn.signal = Signal::kSpawn;
    spawn.count = 1;
    spawn.tasks[0] = static_cast<std::uint32_t>(i);
    auto spawned = command(sockets[0], spawn);
    ASSERT_TRUE(spawned.ok()) << in_worker.tasks[i].name << ": " << spawned.error().message;
    on.tasks[on.count++] = static_cast<std::uint32_t>(i);
  }
  auto turned_on = command(sockets[0], on);
  ASSERT_TRUE(turned_on.ok()) << turned_on.error().message;
  sleep_ms(100);  // warm up: first touches, lazy initialisation

  const std::uint64_t before = cycles_of(*block, n);
  long allocations = 0;
  {
    AllocationGuard guard(AllocationGuard::OnNew::kFail);
    sleep_ms(300);  // every thread is counted: the worker's executive threads, and this one asleep
    allocations = AllocationGuard::count();
  }
  EXPECT_EQ(allocations, 0) << "allocations on a module process's cycle path";
  EXPECT_GT(cycles_of(*block, n), before + 300) << "the worker's tasks cycled while the guard was armed";
  for (std::size_t i = 0; i < n; ++i)
    EXPECT_EQ(block->slot(i)->state.load(std::memory_order_acquire), TaskState::kOn) << in_worker.tasks[i].name;

  ProcessCommand quit;
  quit.kind = ProcessCommandKind::kQuit;
  EXPECT_TRUE(command(sockets[0], quit).ok());
  worker.join();
  EXPECT_EQ(exit_code, 0);

  // What the worker's tasks recorded is in the shared rings, where the main process dumps it: a
  // row for every cycle each task ran (the 2 s rings hold them all).
  std::string dir = std::filesystem::temp_directory_path() / "chimera-rt-dump-XXXXXX";
  ASSERT_NE(::mkdtemp(dir.data()), nullptr);
  auto dumped = (*recorder)->dump(dir, "the test", 0, {}, "");
  ASSERT_TRUE(dumped.ok()) << dumped.error().message;
  std::ifstream file(dir + "/timing.csv");
  const std::string timing((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::filesystem::remove_all(dir);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string row_start = "\n" + in_worker.tasks[i].name + ",";
    std::uint64_t rows = 0;
    for (std::size_t at = timing.find(row_start); at != std::string::npos; at = timing.find(row_start, at + 1)) ++rows;
    const std::uint64_t cycles = block->slot(i)->stats.snapshot().cycles;
    EXPECT_GT(cycles, 0U) << in_worker.tasks[i].name;
    EXPECT_GE(rows, cycles) << in_worker.tasks[i].name << ": its cycles in the shared rings";
  }
  ::close(sockets[0]);
  ::close(sockets[1]);
}

}  // namespace
}  // namespace chimera
