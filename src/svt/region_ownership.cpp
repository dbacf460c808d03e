#include "region_ownership.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <limits>
#include <system_error>
#include <thread>

#include <fmt/format.h>

#include "chimera/svt/detail/shm_layout.hpp"

namespace chimera::svt_detail {

namespace {

using Word = std::atomic_ref<std::uint64_t>;

/// How long a region of another layout that has no owner pid yet (its creator between creating
/// it and its first store) is given before it is called stale.
constexpr auto kOwnerWait = std::chrono::milliseconds(200);

Error sys_error(std::string_view what, const std::string& shm) {
  return make_error(Errc::kSystem, fmt::format("{}({}) failed: {}", what, shm,
                                               std::error_code(errno, std::generic_category()).message()));
}

class FdGuard {
 public:
  explicit FdGuard(int fd) : fd_(fd) {}
  FdGuard(const FdGuard&) = delete;
  FdGuard& operator=(const FdGuard&) = delete;
  ~FdGuard() { ::close(fd_); }

 private:
  int fd_;
};

bool process_alive(std::uint64_t pid) {
  if (pid == 0 || pid > static_cast<std::uint64_t>(std::numeric_limits<pid_t>::max())) return false;
  // EPERM means it exists but belongs to someone else: alive all the same.
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

struct HeaderFacts {
  bool ours = false;  // this layout's magic and fingerprint: its creator held the lock
  std::uint64_t pid = 0;
};

Result<HeaderFacts> read_header(int fd, const std::string& shm) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return sys_error("fstat", shm);
  HeaderFacts facts;
  if (static_cast<std::uint64_t>(st.st_size) < sizeof(Header)) return facts;
  void* p = ::mmap(nullptr, sizeof(Header), PROT_READ, MAP_SHARED, fd, 0);
  if (p == MAP_FAILED) return sys_error("mmap", shm);
  auto* header = object_at<Header>(static_cast<std::byte*>(p), 0);
  // Acquire: pairs with create()'s release store of the magic, after which the rest is written.
  facts.ours =
      Word(header->magic).load(std::memory_order_acquire) == kMagic && header->layout_fingerprint == kLayoutFingerprint;
  // Relaxed: the pid is a value on its own, for a message or the older layouts' rule.
  facts.pid = Word(header->owner_pid).load(std::memory_order_relaxed);
  ::munmap(p, sizeof(Header));
  return facts;
}

// What this process owns, for a signal handler that ends the process the abrupt way: plain
// arrays of lock-free atomics, since a handler may touch nothing else.
struct OwnedNote {
  std::atomic<int> fd{-1};  // -1: free; -2: being filled
  std::atomic<pid_t> pid{0};
  std::array<char, 256> path{};
};
constexpr std::size_t kOwnedNotes = 16;
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): a signal handler reaches only globals
std::array<OwnedNote, kOwnedNotes> g_owned;
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<pid_t>::is_always_lock_free);

bool same_file(int fd, const char* path) noexcept {
  struct stat by_fd {};
  struct stat by_name {};
  return ::fstat(fd, &by_fd) == 0 && ::stat(path, &by_name) == 0 && by_fd.st_dev == by_name.st_dev &&
         by_fd.st_ino == by_name.st_ino;
}

}  // namespace

std::string shm_path(const std::string& shm) { return std::string(kShmDir) + shm; }

void remove_if_same(int fd, const char* path) noexcept {
  // Only the lock holder gets here, and nobody else removes a name while it is held, so the
  // name cannot change between the check and the removal.
  if (same_file(fd, path)) ::unlink(path);
}

Result<Existing> inspect_existing(const std::string& path, const std::string& shm) {
  const auto deadline = std::chrono::steady_clock::now() + kOwnerWait;
  for (;;) {
    const int fd = ::shm_open(shm.c_str(), O_RDONLY, 0);  // the file at `path`, close-on-exec
    if (fd < 0) {
      if (errno == ENOENT) return Existing{Existing::Kind::kGone};
      return sys_error("open", shm);
    }
    FdGuard guard(fd);
    auto facts = read_header(fd, shm);
    if (!facts) return facts.error();
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      if (errno == EWOULDBLOCK) return Existing{Existing::Kind::kLive, facts->pid};
      return sys_error("flock", shm);
    }
    // Nobody holds it. A region of this layout was made under the lock by its creator, who must
    // be gone, whatever its pid has become since. Read again under the lock: the creator may
    // have published between our first look and its death.
    facts = read_header(fd, shm);
    if (!facts) return facts.error();
    const bool stale = facts->ours || (facts->pid != 0 && !process_alive(facts->pid)) ||
                       (facts->pid == 0 && std::chrono::steady_clock::now() >= deadline);
    if (stale) {
      remove_if_same(fd, path.c_str());
      return Existing{Existing::Kind::kReclaimed, facts->pid};
    }
    // Another layout: its creators hold no lock, so the pid is all there is to go by.
    if (facts->pid != 0) return Existing{Existing::Kind::kLive, facts->pid};
    // No pid yet: such a creator may be between creating the region and its first store.
    ::flock(fd, LOCK_UN);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

int note_owned(int fd, const std::string& path) noexcept {
  if (path.size() + 1 > OwnedNote{}.path.size()) return -1;
  for (std::size_t i = 0; i < g_owned.size(); ++i) {
    int free = -1;
    // acq_rel: claims the slot; nobody else fills it until it is free again
    if (!g_owned[i].fd.compare_exchange_strong(free, -2, std::memory_order_acq_rel)) continue;
    std::memcpy(g_owned[i].path.data(), path.c_str(), path.size() + 1);
    g_owned[i].pid.store(::getpid(), std::memory_order_relaxed);  // published by the release below
    // release: a handler that sees the fd (acquire) sees the path and pid written above
    g_owned[i].fd.store(fd, std::memory_order_release);
    return static_cast<int>(i);
  }
  return -1;
}

void forget_owned(int slot) noexcept {
  if (slot < 0) return;
  // release: the slot may be claimed and refilled by the next note_owned
  g_owned[static_cast<std::size_t>(slot)].fd.store(-1, std::memory_order_release);
}

void remove_owned_names_now() noexcept {
  const pid_t self = ::getpid();
  for (auto& note : g_owned) {
    // acquire: pairs with note_owned's release, so the path is whole
    const int fd = note.fd.load(std::memory_order_acquire);
    // A child forked from the owner inherits the notes but owns nothing.
    if (fd < 0 || note.pid.load(std::memory_order_relaxed) != self) continue;
    remove_if_same(fd, note.path.data());
  }
}

}  // namespace chimera::svt_detail
