#include "chimera/exec/write_watch.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

namespace chimera {

WriteWatch::WriteWatch() : fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {}

WriteWatch::~WriteWatch() {
  if (fd_ >= 0) ::close(fd_);
}

void WriteWatch::written() noexcept {
  // acq_rel: pairs with take(); the flag guards only the eventfd write, the values have their own protocol
  if (pending_.exchange(true, std::memory_order_acq_rel)) return;
  if (fd_ >= 0) (void)::eventfd_write(fd_, 1);
}

bool WriteWatch::take() noexcept {
  // The eventfd first, then the flag: a written() between the two finds the flag still up and
  // writes nothing, but its value was published before it, so the reads after this return see it.
  if (fd_ >= 0) {
    eventfd_t drained = 0;
    (void)::eventfd_read(fd_, &drained);
  }
  return pending_.exchange(false, std::memory_order_acq_rel);  // acq_rel: pairs with written()
}

}  // namespace chimera
