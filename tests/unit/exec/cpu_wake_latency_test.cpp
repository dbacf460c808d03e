// The PM QoS hold (src/exec/cpu_wake_latency.hpp): granted where the device can be written, and
// then in force, which the device itself reports (a read gives the system's current target).

#include "exec/cpu_wake_latency.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdint>

#include <gtest/gtest.h>

namespace chimera {
namespace {

TEST(CpuWakeLatency, HeldAtZeroWhereTheSystemGrantsIt) {
  const bool held = detail::hold_cpu_wake_latency();
  EXPECT_EQ(detail::hold_cpu_wake_latency(), held) << "once per process: a second call says the same";
  const int writable = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (writable >= 0) ::close(writable);
  EXPECT_EQ(held, writable >= 0) << "granted exactly where the device can be written";
  if (!held) return;  // a machine without the device or the right: the refusal was the check
  const int fd = ::open("/dev/cpu_dma_latency", O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  std::int32_t target = -1;
  ASSERT_EQ(::read(fd, &target, sizeof target), static_cast<ssize_t>(sizeof target));
  ::close(fd);
  EXPECT_EQ(target, 0) << "the system's target is this process's request while it lives";
}

}  // namespace
}  // namespace chimera
