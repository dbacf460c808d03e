#include "cpu_wake_latency.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdint>

namespace chimera::detail {

bool hold_cpu_wake_latency() noexcept {
  static const bool held = [] {
    // Close-on-exec: a module process's worker is exec'd, and this process's request covers it.
    const int fd = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    if (fd < 0) return false;
    const std::int32_t microseconds = 0;  // the device takes a binary 32-bit value
    if (::write(fd, &microseconds, sizeof microseconds) != static_cast<ssize_t>(sizeof microseconds)) {
      ::close(fd);
      return false;
    }
    return true;  // the descriptor stays open until the process ends: so does the request
  }();
  return held;
}

}  // namespace chimera::detail
