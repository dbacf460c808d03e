#pragma once
// The kernel's PM QoS request for how fast an idle CPU must be able to wake
// (/dev/cpu_dma_latency), held at 0 us for the whole process as cyclictest holds it by default. A
// CPU allowed a deep idle state, and on a virtual machine a halted virtual CPU, starts a released
// task tens of microseconds later: the cost lands on every release of an otherwise idle CPU.

namespace chimera::detail {

/// Asks for an idle wake-up latency of 0 us while this process lives (the request lasts as long as
/// its descriptor is open). Once per process: later calls only say whether it was granted. False
/// where the system refuses it (no such device, or not permitted: it needs root, as SCHED_FIFO).
bool hold_cpu_wake_latency() noexcept;

}  // namespace chimera::detail
