#include "doorbell.hpp"

#include "futex.hpp"

namespace chimera {

void Doorbell::ring() noexcept {
  word_.fetch_add(1, std::memory_order_release);  // release: what the ringer wrote is seen after the wake
  detail::futex_wake_all(word_, detail::FutexScope::kShared);
}

bool Doorbell::wait(std::uint32_t seen, std::int64_t deadline_ns) const noexcept {
  return detail::futex_wait(word_, seen, deadline_ns, detail::FutexScope::kShared);
}

}  // namespace chimera
