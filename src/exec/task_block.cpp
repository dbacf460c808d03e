#include "task_block.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <new>
#include <system_error>
#include <utility>

#include <fmt/format.h>

#include "process_protocol.hpp"

namespace chimera {

namespace {

// Another build of Chimera may lay TaskShared out differently: the fingerprint tells.
constexpr std::uint64_t kMagic = 0x6368696d'7461736bULL;  // "chimtask"
constexpr std::uint64_t kLayout = (std::uint64_t{sizeof(TaskShared)} << 8U) | alignof(TaskShared);

struct alignas(64) Header {
  std::uint64_t magic = kMagic;
  std::uint64_t layout = kLayout;
  std::uint64_t tasks = 0;
  std::atomic<std::int64_t> epoch_ns{0};
  Doorbell requests;
  // A robust mutex's list links point into its owner's memory: only the owner and the kernel
  // read them, never another process, so the rule that shared memory holds no pointer stands.
  std::array<pthread_mutex_t, ProcessCommand::kMaxTasks> life;
};
static_assert(std::atomic<std::int64_t>::is_always_lock_free);

// The header at the start of a mapped block: the one place its bytes are taken for it.
Header* header_of(std::byte* base) noexcept {
  return std::launder(reinterpret_cast<Header*>(
      base));  // NOLINT(cppcoreguidelines-pro-type-reinterpret-cast): a mapping's bytes, laid out by create()
}

constexpr std::size_t kSlotsOffset =
    (sizeof(Header) + alignof(TaskShared) - 1) / alignof(TaskShared) * alignof(TaskShared);

std::size_t block_bytes(std::size_t tasks) { return kSlotsOffset + tasks * sizeof(TaskShared); }

Error sys_error(std::string_view what) {
  return make_error(Errc::kSystem,
                    fmt::format("the task block: {} failed: {}", what, std::generic_category().message(errno)));
}

}  // namespace

Result<TaskBlock> TaskBlock::create(std::size_t tasks) {
  // A command to a worker names tasks by index in arrays of fixed size (process_protocol.hpp).
  if (tasks > ProcessCommand::kMaxTasks)
    return make_error(Errc::kInvalidInput, fmt::format("a subsystem with module processes (process:) has at most {} "
                                                       "tasks; this one has {}",
                                                       ProcessCommand::kMaxTasks, tasks));
  TaskBlock b;
  b.fd_ = ::memfd_create("chimera-tasks", MFD_CLOEXEC);
  if (b.fd_ < 0) return sys_error("memfd_create");
  b.bytes_ = block_bytes(tasks);
  b.tasks_ = tasks;
  // Reserved up front, as the global table is: a full tmpfs is an error here, never a SIGBUS later.
  if (const int rc = ::posix_fallocate(b.fd_, 0, static_cast<off_t>(b.bytes_)); rc != 0) {
    errno = rc;  // it returns the error rather than setting errno
    return sys_error("posix_fallocate");
  }
  void* p = ::mmap(nullptr, b.bytes_, PROT_READ | PROT_WRITE, MAP_SHARED, b.fd_, 0);
  if (p == MAP_FAILED) return sys_error("mmap");
  b.base_ = static_cast<std::byte*>(p);
  auto* header = new (b.base_) Header{};
  header->tasks = tasks;
  pthread_mutexattr_t attr;
  pthread_mutexattr_init(&attr);
  pthread_mutexattr_setpshared(&attr, PTHREAD_PROCESS_SHARED);
  pthread_mutexattr_setrobust(&attr, PTHREAD_MUTEX_ROBUST);
  for (auto& m : header->life) pthread_mutex_init(&m, &attr);
  pthread_mutexattr_destroy(&attr);
  for (std::size_t i = 0; i < tasks; ++i) new (b.base_ + kSlotsOffset + i * sizeof(TaskShared)) TaskShared{};
  return b;
}

Result<TaskBlock> TaskBlock::attach(int fd, std::size_t tasks) {
  TaskBlock b;
  b.fd_ = fd;
  struct stat st {};
  if (::fstat(fd, &st) != 0) return sys_error("fstat");
  if (static_cast<std::size_t>(st.st_size) != block_bytes(tasks))
    return make_error(Errc::kSystem, fmt::format("the task block has {} bytes, not the {} of {} tasks", st.st_size,
                                                 block_bytes(tasks), tasks));
  b.bytes_ = block_bytes(tasks);
  b.tasks_ = tasks;
  void* p = ::mmap(nullptr, b.bytes_, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (p == MAP_FAILED) return sys_error("mmap");
  b.base_ = static_cast<std::byte*>(p);
  const Header* header = header_of(b.base_);
  if (header->magic != kMagic || header->layout != kLayout || header->tasks != tasks)
    return make_error(Errc::kSystem, "the task block was made by another build of Chimera (its layout differs)");
  return b;
}

TaskBlock::TaskBlock(TaskBlock&& other) noexcept
    : base_(std::exchange(other.base_, nullptr)),
      bytes_(other.bytes_),
      tasks_(other.tasks_),
      fd_(std::exchange(other.fd_, -1)) {}

TaskBlock& TaskBlock::operator=(TaskBlock&& other) noexcept {
  if (this != &other) {
    release();
    base_ = std::exchange(other.base_, nullptr);
    bytes_ = other.bytes_;
    tasks_ = other.tasks_;
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

TaskBlock::~TaskBlock() { release(); }

void TaskBlock::release() noexcept {
  if (base_ != nullptr) ::munmap(base_, bytes_);
  if (fd_ >= 0) ::close(fd_);
  base_ = nullptr;
  fd_ = -1;
}

TaskShared* TaskBlock::slot(std::size_t task) const noexcept {
  return std::launder(reinterpret_cast<TaskShared*>(base_ + kSlotsOffset + task * sizeof(TaskShared)));
}

pthread_mutex_t* TaskBlock::life(std::size_t process) const noexcept { return &header_of(base_)->life[process]; }

Doorbell& TaskBlock::requests_bell() const noexcept { return header_of(base_)->requests; }

std::int64_t TaskBlock::epoch_ns() const noexcept {
  // Acquire: pairs with set_epoch_ns, written before any worker starts.
  return header_of(base_)->epoch_ns.load(std::memory_order_acquire);
}

void TaskBlock::set_epoch_ns(std::int64_t epoch_ns) noexcept {
  // Release: a worker that reads it also sees the slots as they were made.
  header_of(base_)->epoch_ns.store(epoch_ns, std::memory_order_release);
}

}  // namespace chimera
