#include "chimera/exec/write_watch.hpp"

#include "futex.hpp"

namespace chimera {

void WriteWatch::written() noexcept {
  // acq_rel: the release publishes the values before the news to take(); the acquire sees the
  // watcher's kSleeping, so that a sleeping watcher is always woken.
  const std::uint32_t before = word_.fetch_or(kNews, std::memory_order_acq_rel);
  if ((before & kNews) == 0 && (before & kSleeping) != 0) detail::futex_wake_all(word_);
}

bool WriteWatch::take() noexcept {
  return (word_.fetch_and(~kNews, std::memory_order_acq_rel) & kNews) != 0;  // acq_rel: pairs with written()
}

void WriteWatch::wait_until(std::int64_t deadline_ns) noexcept {
  // acq_rel: kSleeping is seen by every written() after it, and news before it is seen here. A
  // written() between this and the futex's sleep changes the word, and the futex does not sleep.
  const std::uint32_t before = word_.fetch_or(kSleeping, std::memory_order_acq_rel);
  if ((before & kNews) == 0) (void)detail::futex_wait(word_, kSleeping, deadline_ns);
  // acquire: what the waker wrote before its news (a stop flag) is seen after the wake. A
  // written() that still finds kSleeping set makes one needless wake, nothing worse.
  word_.fetch_and(~kSleeping, std::memory_order_acquire);
}

}  // namespace chimera
