// The global table's lifetime: creating, replacing, attaching to and removing its POSIX shared
// memory region, and the directory lookups. The protocol is in global_table_protocol.cpp.

#include "chimera/svt/global_table.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <limits>
#include <new>
#include <set>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "chimera/core/identifier.hpp"
#include "chimera/svt/detail/shm_layout.hpp"
#include "region_ownership.hpp"

namespace chimera {

namespace {

using svt_detail::DirEntry;
using svt_detail::Header;
using svt_detail::object_at;
using Word = std::atomic_ref<std::uint64_t>;

/// Largest payload of one variable; keeps byte counts in 32 bits everywhere.
constexpr std::uint64_t kMaxVarBytes = std::uint64_t{1} << 28;

/// The unit of memory protection (Placement::kPagePerVariable).
std::uint64_t page_bytes() { return static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)); }

Error sys_error(std::string_view what, const std::string& shm) {
  return make_error(Errc::kSystem, fmt::format("{}({}) failed: {}", what, shm,
                                               std::error_code(errno, std::generic_category()).message()));
}

/// Closes a descriptor on every path out of a function.
class FdGuard {
 public:
  explicit FdGuard(int fd) : fd_(fd) {}
  FdGuard(const FdGuard&) = delete;
  FdGuard& operator=(const FdGuard&) = delete;
  ~FdGuard() {
    if (fd_ >= 0) ::close(fd_);
  }
  /// Hands the descriptor over: the guard no longer closes it.
  int release() noexcept { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

Result<void> check_subsystem_name(std::string_view name) {
  if (name.empty() || name.size() > 200) {
    return make_error(Errc::kInvalidInput, fmt::format("subsystem name '{}' must have 1 to 200 characters", name));
  }
  for (const char c : name) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!ok) {
      return make_error(Errc::kInvalidInput,
                        fmt::format("subsystem name '{}' may hold only letters, digits, '_', '-' and '.'", name));
    }
  }
  return {};
}

// The loader checks names against kMaxVariableName: it must be what the region's field holds.
static_assert(svt_detail::kNameCapacity == kMaxVariableName + 1);

Result<void> check_vars(std::span<const VarSpec> vars) {
  if (vars.size() > std::numeric_limits<std::uint32_t>::max()) {
    return make_error(Errc::kInvalidInput, "too many state variables");
  }
  std::set<std::string_view> names;
  for (const VarSpec& var : vars) {
    if (var.name.empty() || var.name.size() >= svt_detail::kNameCapacity) {
      return make_error(Errc::kInvalidInput, fmt::format("state variable name '{}' must have 1 to {} characters",
                                                         var.name, svt_detail::kNameCapacity - 1));
    }
    if (!names.insert(var.name).second) {
      return make_error(Errc::kInvalidInput, fmt::format("state variable '{}' is declared twice", var.name));
    }
    if (var.shape.count == 0 || elem_size(var.shape.type) == 0) {
      return make_error(Errc::kInvalidInput, fmt::format("state variable '{}' has no elements", var.name));
    }
    if (var.shape.bytes() > kMaxVarBytes) {
      return make_error(Errc::kInvalidInput, fmt::format("state variable '{}' ({}) is larger than {} bytes", var.name,
                                                         to_string(var.shape), kMaxVarBytes));
    }
  }
  return {};
}

/// Checks that an attached region's directory stays inside it, so a damaged or foreign region
/// is refused here rather than crashing a task later.
Result<void> check_layout(std::byte* base, std::uint64_t mapped, const std::string& shm) {
  const auto* header = object_at<Header>(base, 0);
  auto bad = [&](std::string_view why) {
    return make_error(Errc::kSystem, fmt::format("shared memory {} is damaged: {}", shm, why));
  };
  if (header->total_size > mapped) return bad("it is smaller than its header says");
  const std::uint64_t dir_end = header->directory_offset + std::uint64_t{header->var_count} * sizeof(DirEntry);
  if (header->directory_offset < sizeof(Header) || dir_end > header->total_size) return bad("directory out of range");
  for (std::uint32_t v = 0; v < header->var_count; ++v) {
    const DirEntry* e = svt_detail::dir_entry(base, v);
    const std::uint64_t bytes = elem_size(static_cast<ElemType>(e->elem_type)) * std::uint64_t{e->count};
    if (std::memchr(e->name.data(), '\0', e->name.size()) == nullptr) return bad("a name is not terminated");
    if (e->elem_type > static_cast<std::uint8_t>(ElemType::kU8) || e->count == 0 || bytes > kMaxVarBytes ||
        e->payload_words != svt_detail::payload_words(bytes)) {
      return bad(fmt::format("variable {} has an impossible shape", v));
    }
    if (e->block_offset % svt_detail::kCacheLine != 0 || e->block_offset < dir_end ||
        e->block_offset + svt_detail::block_bytes(e->payload_words) > header->total_size) {
      return bad(fmt::format("variable {} lies outside the region", v));
    }
  }
  return {};
}

}  // namespace

Result<GlobalTable> GlobalTable::create(std::string_view subsystem_name, std::span<const VarSpec> vars,
                                        Placement placement) {
  if (auto r = check_subsystem_name(subsystem_name); !r) return r.error();
  if (auto r = check_vars(vars); !r) return r.error();
  const std::string shm = fmt::format("/chimera_{}", subsystem_name);

  // Layout first: the directory right after the header, then one 64-aligned block per variable;
  // or, a page apart, the header alone on the first page, then the directory, then each block
  // starting a page of its own.
  const std::uint64_t unit = placement == Placement::kPagePerVariable ? page_bytes() : svt_detail::kCacheLine;
  const std::uint64_t dir_offset =
      placement == Placement::kPagePerVariable ? page_bytes() : svt_detail::directory_offset();
  const std::uint64_t dir_end = dir_offset + vars.size() * sizeof(DirEntry);
  std::uint64_t total = svt_detail::round_up(dir_end, unit);
  std::vector<std::uint64_t> block_offsets;
  block_offsets.reserve(vars.size());
  for (const VarSpec& var : vars) {
    block_offsets.push_back(total);
    total = svt_detail::round_up(total + svt_detail::block_bytes(svt_detail::payload_words(var.shape.bytes())), unit);
  }

  // The region is made whole before it has a name: an unnamed file in /dev/shm, locked, its
  // memory reserved, laid out; then linked under its name in one step that fails if the name is
  // taken. So a region under a name is always complete and always locked by a live owner, or
  // stale; and a creator that dies on the way leaves nothing behind.
  const std::string path = svt_detail::shm_path(shm);
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-vararg): open(2) is the one call that makes an O_TMPFILE
  const int fd = ::open(svt_detail::kShmDir, O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd < 0) return sys_error("open(O_TMPFILE) in /dev/shm for", shm);
  // Closed on every path out; a table that is made keeps it open (the lock) until release().
  FdGuard guard(fd);
  // The owner's lock (region_ownership.hpp): nobody else can see this file yet, so it is ours.
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) return sys_error("flock", shm);
  // O_TMPFILE applied the umask; state the mode outright.
  if (::fchmod(fd, 0600) != 0) return sys_error("fchmod", shm);
  if (::ftruncate(fd, static_cast<off_t>(total)) != 0) return sys_error("ftruncate", shm);
  // Every page now, not at its first touch: a full /dev/shm is this message, never a SIGBUS in
  // the middle of a run.
  if (const int e = ::posix_fallocate(fd, 0, static_cast<off_t>(total)); e != 0) {
    if (e == ENOSPC) {
      struct statvfs fs {};
      const std::uint64_t free_bytes =
          ::fstatvfs(fd, &fs) == 0 ? std::uint64_t{fs.f_bavail} * fs.f_frsize : std::uint64_t{0};
      return make_error(Errc::kSystem, fmt::format("no room in {} for the state variable table of subsystem '{}': "
                                                   "it needs {} bytes, {} are free (shared memory {})",
                                                   svt_detail::kShmDir, subsystem_name, total, free_bytes, shm));
    }
    errno = e;
    return sys_error("posix_fallocate", shm);
  }
  void* p = ::mmap(nullptr, total, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (p == MAP_FAILED) return sys_error("mmap", shm);

  GlobalTable table;
  table.shm_name_ = shm;
  table.base_ = static_cast<std::byte*>(p);
  table.mapped_bytes_ = total;

  // ftruncate zero-filled the region: every version, seq and payload word starts at 0, and the
  // placement news below default-initialise, leaving those zeros.
  auto* header = new (table.base_) Header;  // default-init: no store over the zeros
  // Relaxed: the region has no name yet, so nobody else reads it; the pid is for messages (and
  // tells a forked child, which inherits the mapping, that it is not the creator).
  Word(header->owner_pid).store(static_cast<std::uint64_t>(::getpid()), std::memory_order_relaxed);
  header->layout_version = svt_detail::kLayoutVersion;
  header->layout_fingerprint = svt_detail::kLayoutFingerprint;
  header->var_count = static_cast<std::uint32_t>(vars.size());
  header->directory_offset = dir_offset;
  header->total_size = total;
  for (std::size_t v = 0; v < vars.size(); ++v) {
    auto* e = new (table.base_ + dir_offset + v * sizeof(DirEntry)) DirEntry;
    std::memcpy(e->name.data(), vars[v].name.data(), vars[v].name.size());
    e->count = vars[v].shape.count;
    e->elem_type = static_cast<std::uint8_t>(vars[v].shape.type);
    e->payload_words = static_cast<std::uint32_t>(svt_detail::payload_words(vars[v].shape.bytes()));
    e->block_offset = block_offsets[v];
  }
  // Release: a process that attaches and sees the magic (acquire) sees the whole layout above.
  Word(header->magic).store(svt_detail::kMagic, std::memory_order_release);

  // Noted before it has a name, so that a signal that ends the process the abrupt way from the
  // moment it has one removes it (the note checks the name is still this region's).
  table.owned_note_ = svt_detail::note_owned(fd, path);
  // An existing name is refused if its owner lives and reclaimed if it is gone. Three rounds
  // cover a name removed or taken again meanwhile.
  const std::string self = fmt::format("/proc/self/fd/{}", fd);
  bool named = false;
  for (int round = 0; round < 3 && !named; ++round) {
    if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, path.c_str(), AT_SYMLINK_FOLLOW) == 0) {
      named = true;
      break;
    }
    if (errno != EEXIST) return sys_error("linkat", shm);
    auto existing = svt_detail::inspect_existing(path, shm);
    if (!existing) return existing.error();
    if (existing->kind == svt_detail::Existing::Kind::kLive) {
      return make_error(Errc::kSystem, fmt::format("subsystem '{}' is already running (pid {}); shared memory {}",
                                                   subsystem_name, existing->pid, shm));
    }
  }
  if (!named) {
    return make_error(Errc::kSystem, fmt::format("could not create shared memory {}: another process keeps "
                                                 "creating it",
                                                 shm));
  }
  table.owner_ = true;
  table.lock_fd_ = guard.release();
  table.locate_blocks();
  return table;
}

Result<GlobalTable> GlobalTable::attach(std::string_view subsystem_name) {
  if (auto r = check_subsystem_name(subsystem_name); !r) return r.error();
  const std::string shm = fmt::format("/chimera_{}", subsystem_name);
  const int fd = ::shm_open(shm.c_str(), O_RDWR, 0);
  if (fd < 0) {
    if (errno == ENOENT) {
      return make_error(Errc::kNotFound,
                        fmt::format("subsystem '{}' is not running (no shared memory {})", subsystem_name, shm));
    }
    return sys_error("shm_open", shm);
  }
  FdGuard guard(fd);
  struct stat st {};
  if (::fstat(fd, &st) != 0) return sys_error("fstat", shm);
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size < sizeof(Header)) {
    return make_error(Errc::kSystem, fmt::format("shared memory {} is not a state variable table (or is "
                                                 "still being created)",
                                                 shm));
  }
  void* p = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (p == MAP_FAILED) return sys_error("mmap", shm);

  GlobalTable table;  // unmaps on every error path below
  table.shm_name_ = shm;
  table.base_ = static_cast<std::byte*>(p);
  table.mapped_bytes_ = size;
  auto* header = object_at<Header>(table.base_, 0);
  // Acquire: pairs with create()'s release store of the magic, so the layout is complete.
  if (Word(header->magic).load(std::memory_order_acquire) != svt_detail::kMagic) {
    return make_error(Errc::kSystem, fmt::format("shared memory {} is not a state variable table (or is "
                                                 "still being created)",
                                                 shm));
  }
  // The version word first: it is where every layout has kept it, so a region of an older layout
  // is told apart without reading past what it has.
  if (header->layout_version != svt_detail::kLayoutVersion ||
      header->layout_fingerprint != svt_detail::kLayoutFingerprint) {
    return make_error(Errc::kSystem, fmt::format("shared memory {} was made by another version of Chimera (layout "
                                                 "{:08x}); this program understands layout {:08x}",
                                                 shm, header->layout_version, svt_detail::kLayoutVersion));
  }
  if (auto r = check_layout(table.base_, size, shm); !r) return r.error();
  table.locate_blocks();
  return table;
}

GlobalTable::GlobalTable(GlobalTable&& other) noexcept
    : shm_name_(std::move(other.shm_name_)),
      base_(std::exchange(other.base_, nullptr)),
      blocks_(std::move(other.blocks_)),
      mapped_bytes_(std::exchange(other.mapped_bytes_, 0)),
      owner_(std::exchange(other.owner_, false)),
      lock_fd_(std::exchange(other.lock_fd_, -1)),
      owned_note_(std::exchange(other.owned_note_, -1)) {}

GlobalTable& GlobalTable::operator=(GlobalTable&& other) noexcept {
  if (this != &other) {
    release();
    shm_name_ = std::move(other.shm_name_);
    base_ = std::exchange(other.base_, nullptr);
    blocks_ = std::move(other.blocks_);
    mapped_bytes_ = std::exchange(other.mapped_bytes_, 0);
    owner_ = std::exchange(other.owner_, false);
    lock_fd_ = std::exchange(other.lock_fd_, -1);
    owned_note_ = std::exchange(other.owned_note_, -1);
  }
  return *this;
}

GlobalTable::~GlobalTable() { release(); }

void GlobalTable::release() noexcept {
  if (base_ == nullptr) return;
  // A child forked from the owner inherits this handle but must not remove the parent's region:
  // only the process named in the header unlinks it.
  auto* header = object_at<Header>(base_, 0);
  // Relaxed: the pid was stored by this process (or before the magic we acquired in attach).
  const bool creator_here =
      Word(header->owner_pid).load(std::memory_order_relaxed) == static_cast<std::uint64_t>(::getpid());
  ::munmap(base_, mapped_bytes_);
  // The name goes while the lock is still held (closing the descriptor drops it), and only if it
  // is still this region's.
  if (owner_ && creator_here && lock_fd_ >= 0)
    svt_detail::remove_if_same(lock_fd_, svt_detail::shm_path(shm_name_).c_str());
  svt_detail::forget_owned(owned_note_);  // before the descriptor it names is closed
  if (lock_fd_ >= 0) ::close(lock_fd_);
  base_ = nullptr;
  blocks_.clear();
  mapped_bytes_ = 0;
  owner_ = false;
  lock_fd_ = -1;
  owned_note_ = -1;
}

void GlobalTable::remove_owned_names_now() noexcept { svt_detail::remove_owned_names_now(); }

std::size_t GlobalTable::reclaim_stale(std::string_view name_prefix) {
  const std::string prefix = fmt::format("chimera_{}", name_prefix);
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(svt_detail::kShmDir, ec))
    if (const std::string name = entry.path().filename().string(); name.rfind(prefix, 0) == 0) names.push_back(name);
  std::size_t reclaimed = 0;
  for (const auto& name : names) {
    // inspect_existing() removes the name only when nobody holds the region's lock.
    auto existing = svt_detail::inspect_existing(svt_detail::shm_path("/" + name), "/" + name);
    if (existing && existing->kind == svt_detail::Existing::Kind::kReclaimed) ++reclaimed;
  }
  return reclaimed;
}

Result<void> GlobalTable::restrict_writes(std::span<const VarIndex> writable) {
  const auto* header = object_at<Header>(base_, 0);
  const std::uint64_t page = page_bytes();
  const auto refuse = [&](std::string_view why) {
    return make_error(Errc::kInvalidInput, fmt::format("shared memory {}: cannot let this process write only its own "
                                                       "variables: {}",
                                                       shm_name_, why));
  };
  if (header->directory_offset % page != 0 || mapped_bytes_ % page != 0)
    return refuse("it is not laid out a page apart");
  for (VarIndex v = 0; v < header->var_count; ++v)
    if (svt_detail::dir_entry(base_, v)->block_offset % page != 0) return refuse("a variable shares a page");
  // Everything past the header page read-only, then each of its variables' pages writable again.
  if (::mprotect(base_ + page, mapped_bytes_ - page, PROT_READ) != 0) return sys_error("mprotect", shm_name_);
  for (const VarIndex v : writable) {
    if (v >= header->var_count) return refuse(fmt::format("no variable {}", v));
    const DirEntry* e = svt_detail::dir_entry(base_, v);
    const std::uint64_t bytes = svt_detail::round_up(svt_detail::block_bytes(e->payload_words), page);
    if (::mprotect(base_ + e->block_offset, bytes, PROT_READ | PROT_WRITE) != 0)
      return sys_error("mprotect", shm_name_);
  }
  return {};
}

void GlobalTable::locate_blocks() {
  const auto* header = object_at<Header>(base_, 0);
  blocks_.clear();
  blocks_.reserve(header->var_count);
  for (VarIndex v = 0; v < header->var_count; ++v) blocks_.push_back(svt_detail::block_ref(base_, v));
}

std::size_t GlobalTable::size() const noexcept { return mapped_bytes_; }

std::optional<VarIndex> GlobalTable::find(std::string_view var_name) const {
  const auto* header = object_at<Header>(base_, 0);
  for (VarIndex v = 0; v < header->var_count; ++v) {
    if (name(v) == var_name) return v;
  }
  return std::nullopt;
}

std::string_view GlobalTable::name(VarIndex v) const noexcept {
  const DirEntry* e = svt_detail::dir_entry(base_, v);
  return {e->name.data(), ::strnlen(e->name.data(), e->name.size())};
}

VarShape GlobalTable::shape(VarIndex v) const noexcept {
  const DirEntry* e = svt_detail::dir_entry(base_, v);
  return VarShape{static_cast<ElemType>(e->elem_type), e->count};
}

}  // namespace chimera
