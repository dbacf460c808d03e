#pragma once
// Where `chimera run` puts its ordinary threads (the network API, the stream samplers, the DDS
// bridge, the supervisor, the service thread): on the CPUs that no real-time task runs on, when
// there are any. This kernel's default preemption model (PREEMPT_NONE, as most distributions'
// "server" builds and this project's VMs have) does not preempt a thread inside the kernel: a
// real-time task released while an ordinary thread of its CPU is in a send() or a wake-up waits
// until that thread leaves the kernel. Measured with 10 WebSocket clients streaming 20 variables
// at 1 kHz (docs/scheduling.md, "Ordinary threads"): Figure 4's tasks' release latency p99 was
// 1.14x to 1.42x of without; with these threads and the clients off their CPU, 0.90x to 0.98x.

#include <vector>

namespace chimera::cli {

/// The CPUs left to ordinary work: those this process may use that none of `realtime_cpus` is.
/// Empty when every usable CPU runs a real-time task (or the list names none).
[[nodiscard]] std::vector<int> ordinary_cpus(const std::vector<int>& realtime_cpus);

/// Moves every thread of this process that is not real-time (SCHED_OTHER, SCHED_BATCH,
/// SCHED_IDLE), the calling one included, to `cpus`; the threads they start later inherit it.
/// Does nothing for an empty list, or when no thread of this process got a real-time priority
/// (SCHED_FIFO refused, or the virtual clock): then the task threads are ordinary ones too, and
/// are best left where the kernel balances them. Returns whether it moved them.
bool keep_ordinary_threads_on(const std::vector<int>& cpus);

}  // namespace chimera::cli
