#include "chimera/control/module_process_main.hpp"

#include <pthread.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "chimera/config/verify.hpp"
#include "chimera/svt/global_table.hpp"
#include "exec/event_log.hpp"
#include "exec/executive.hpp"
#include "exec/process_protocol.hpp"
#include "exec/task_block.hpp"
#include "exec/task_set.hpp"
#include "flight_recorder.hpp"
#include "reconfig/request_board.hpp"

namespace chimera {

namespace {

void reply(int socket_fd, const Result<void>& r, std::int64_t value = -1) {
  const ProcessReply message = ProcessReply::from(r, value);
  (void)::send(socket_fd, &message, sizeof message, MSG_NOSIGNAL);
}

std::vector<std::size_t> indices(const std::array<std::uint32_t, ProcessCommand::kMaxTasks>& list, std::uint32_t n) {
  const std::size_t count = std::min<std::size_t>(n, ProcessCommand::kMaxTasks);
  return {list.begin(), list.begin() + static_cast<std::ptrdiff_t>(count)};
}

CommitOutcome commit(Executive& executive, const ProcessCommand& c, const std::vector<bool>& mine,
                     const ResolvedSubsystem& resolved) {
  SwitchCommit part;
  part.leaving = indices(c.tasks, c.count);
  part.joining = indices(c.joining, c.joining_count);
  for (const std::size_t i : indices(c.target, c.target_count)) {
    if (i >= resolved.tasks.size()) return {-1, make_error(Errc::kInvalidInput, fmt::format("no task {}", i))};
    part.target.push_back(resolved.tasks[i].spec->name);
  }
  for (const auto* list : {&part.leaving, &part.joining})
    for (const std::size_t i : *list)
      if (i >= mine.size() || !mine[i])
        return {-1, make_error(Errc::kInvalidInput, fmt::format("task {} is not mine", i))};
  part.at_ns = c.at_ns;
  part.part = static_cast<SwitchCommit::Part>(c.part);
  return executive.commit_switch(part);
}

Result<void> carry_out(Executive& executive, const ProcessCommand& c, const std::vector<bool>& mine) {
  const std::vector<std::size_t> tasks = indices(c.tasks, c.count);
  for (const std::size_t i : tasks)
    if (i >= mine.size() || !mine[i]) return make_error(Errc::kInvalidInput, fmt::format("task {} is not mine", i));
  if (tasks.empty() && c.kind != ProcessCommandKind::kQuit) return make_error(Errc::kInvalidInput, "no task");
  switch (c.kind) {
    case ProcessCommandKind::kSignal: return executive.signal(tasks.front(), c.signal);
    case ProcessCommandKind::kTurnOnTogether: return executive.turn_on_together(tasks);
    case ProcessCommandKind::kReinit: return executive.reinit(tasks.front());
    case ProcessCommandKind::kQuit:
    case ProcessCommandKind::kCommit: break;
  }
  return {};
}

// The variables the tasks of `process` produce (out-vars and out-consts): all it may write.
std::vector<VarIndex> written_by(const ResolvedSubsystem& resolved, const GlobalTable& table,
                                 const std::string& process) {
  std::vector<VarIndex> written;
  for (const ResolvedTask& t : resolved.tasks) {
    if (t.spec->process != process) continue;
    for (const PortBinding& b : t.bindings)
      if (b.kind == PortKind::kOutVar || b.kind == PortKind::kOutConst)
        if (const auto v = table.find(b.variable)) written.push_back(*v);
  }
  return written;
}

// The main process's commands, until it says quit (0) or is gone (the process ends at once).
int serve_commands(int sock, Executive& executive, const std::vector<bool>& mine, const ResolvedSubsystem& resolved,
                   pthread_mutex_t* life) {
  for (;;) {
    ProcessCommand c;
    const ssize_t got = ::recv(sock, &c, sizeof c, 0);
    if (got == 0 || (got < 0 && errno != EINTR)) {
      // The main process is gone (EOF): nobody will read the tasks' figures or send them off.
      // End at once, so that a crashed main process never leaves a worker running on.
      std::_Exit(0);
    }
    if (got != static_cast<ssize_t>(sizeof c)) continue;
    if (c.kind == ProcessCommandKind::kQuit) {
      executive.shutdown();
      // Given back by hand: the block is unmapped on the way out, and the kernel can release a
      // robust lock only where it is still mapped.
      if (life != nullptr) pthread_mutex_unlock(life);
      reply(sock, Result<void>{});
      return 0;
    }
    if (c.kind == ProcessCommandKind::kCommit) {
      const CommitOutcome outcome = commit(executive, c, mine, resolved);
      reply(sock, outcome.fault, outcome.joins_from_ns);
      continue;
    }
    reply(sock, carry_out(executive, c, mine));
  }
}

}  // namespace

int run_module_process(const SubsystemSpec& spec, const Registry& registry, const ModuleProcessArgs& args) {
  const int sock = args.socket_fd;
  const Resolution resolution = resolve_subsystem(spec, registry);
  const ResolvedSubsystem& resolved = resolution.subsystem;
  auto table = GlobalTable::attach(args.table);
  if (!table) {
    reply(sock, table.error());
    return 1;
  }
  auto block = TaskBlock::attach(args.block_fd, resolved.tasks.size());
  if (!block) {
    reply(sock, block.error());
    return 1;
  }
  // A stray pointer of a module here may write its own tasks' variables, and nothing else of the
  // table: every other variable's pages, and the directory's, are read-only in this process.
  if (auto restricted = table->restrict_writes(written_by(resolved, *table, args.process)); !restricted) {
    reply(sock, restricted.error());
    return 1;
  }
  // Every task's shared part is the block's, as in the main process: its own tasks keep there what
  // the main process must see, and the others (never spawned here) what its producers wake them by.
  std::vector<TaskShared*> shared(resolved.tasks.size(), nullptr);
  std::vector<bool> mine(resolved.tasks.size(), false);
  for (std::size_t i = 0; i < resolved.tasks.size(); ++i) {
    shared[i] = block->slot(i);
    mine[i] = resolved.tasks[i].spec->process == args.process;
  }
  if (std::find(mine.begin(), mine.end(), true) == mine.end()) {
    reply(sock, make_error(Errc::kInvalidInput, fmt::format("the file has no task in process {}", args.process)));
    return 1;
  }
  // Its tasks' switch requests go into the block's slots and ring its bell, where the main
  // process's service thread serves them as it does its own tasks'.
  SubsystemRequestBoard requests(spec.configuration_names(), *block);
  TaskSet tasks(resolved, *table, &requests, shared);
  for (Task* t : tasks.pointers()) t->set_rt_check(args.rt_check);
  // Its tasks record what they write and how they cycle in the rings the main process dumps.
  std::unique_ptr<FlightRecorder> recorder;
  if (args.history_fd >= 0) {
    auto attached = FlightRecorder::attach(resolved, *table, tasks, args.record_seconds, args.history_fd);
    if (!attached) {
      reply(sock, attached.error());
      return 1;
    }
    recorder = std::move(*attached);
  }
  EventLog events(tasks.size());  // the executive's own events; the tasks' are in the block, for the main process
  const ConfigurationSpec* start = spec.find_configuration(args.configuration.value_or(spec.start));
  ExecutiveSetup setup;
  setup.clock = ClockKind::kReal;
  setup.realtime_priorities = args.realtime_priorities;
  setup.measure_cpu_time = args.measure_cpu_time;
  setup.subsystem = &resolved;
  setup.table = &*table;
  setup.tasks = tasks.pointers();
  if (start != nullptr) setup.configuration = start->tasks;
  setup.events = &events;
  setup.hosted = mine;
  setup.epoch_ns = block->epoch_ns();
  setup.bell_fds.assign(resolved.tasks.size(), -1);
  for (const auto& [task, fd] : args.bells)
    if (task < resolved.tasks.size()) setup.bell_fds[task] = fd;
  std::unique_ptr<Executive> executive = make_executive(std::move(setup));
  // Held until this process ends, however it ends: the kernel hands it to the main process's
  // watcher as this thread exits, long before the pidfd says the process is gone.
  // The thread that holds the life lock runs at the lowest real-time priority: it only waits on
  // its socket, and when the process is killed it is scheduled to exit (and so to free the
  // lock) ahead of every ordinary thread of the machine.
  if (args.realtime_priorities) {
    sched_param lowest{};
    lowest.sched_priority = 1;
    (void)pthread_setschedparam(pthread_self(), SCHED_FIFO, &lowest);
  }
  pthread_mutex_t* life = nullptr;
  if (args.life >= 0 && static_cast<std::size_t>(args.life) < ProcessCommand::kMaxTasks) {
    life = block->life(static_cast<std::size_t>(args.life));
    if (pthread_mutex_lock(life) == EOWNERDEAD) pthread_mutex_consistent(life);  // a previous start's
  }
  reply(sock, Result<void>{});  // ready
  return serve_commands(sock, *executive, mine, resolved, life);
}

}  // namespace chimera
