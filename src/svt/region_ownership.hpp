#pragma once
// Who owns a global table's region, told by a lock rather than by a pid: the creator holds an
// exclusive flock on the region's file for as long as it lives, and the kernel drops the lock
// when the process ends, however it ends. So a region nobody holds is stale whatever became of
// the pid in its header (reused by an unrelated live process, or by this very process), and a
// region somebody holds is live. The pid stays in the header for messages only.
//
// Names are removed only by whoever holds the region's lock, and only after checking that the
// name still refers to that region, so that a reclaimer never removes a region a newer run has
// just published under the same name. Private to the svt part. Not real-time safe, except
// remove_owned_names_now().

#include <cstdint>
#include <string>

#include "chimera/core/result.hpp"

namespace chimera::svt_detail {

/// Where POSIX shared memory objects live on Linux (glibc's shm_open opens files there).
inline constexpr const char* kShmDir = "/dev/shm";

/// "/dev/shm/chimera_fig4" for "/chimera_fig4".
std::string shm_path(const std::string& shm);

/// What create() found under a name that already exists.
struct Existing {
  enum class Kind {
    kGone,       // nothing there (any more): try again
    kReclaimed,  // a stale region: its name has been removed, try again
    kLive,       // a live owner holds it: refuse
  } kind;
  std::uint64_t pid = 0;  // the owner's pid as its header says, for the message
};

/// Looks at the region under `path` (shared memory object `shm`, for messages): live if its
/// owner's lock is held; if not, and it is a region of this layout, its owner is gone and its
/// name is removed. A region of another layout (an older Chimera, which held no lock) falls back
/// on the pid in its header, and one with no pid yet gets a moment for its creator to store one.
Result<Existing> inspect_existing(const std::string& path, const std::string& shm);

/// Removes `path` if it still names the file open as `fd` (whose lock the caller holds).
void remove_if_same(int fd, const char* path) noexcept;

/// Notes that this process owns the region open as `fd` under `path`, for
/// remove_owned_names_now(). Returns the note's slot, or -1 if every slot is taken (the region
/// is then only removed the ordinary way).
int note_owned(int fd, const std::string& path) noexcept;
/// Forgets the note in `slot` (-1: none). Call before closing its descriptor.
void forget_owned(int slot) noexcept;
/// Removes the name of every region this process noted and still owns (each checked as
/// remove_if_same does). Async-signal-safe.
void remove_owned_names_now() noexcept;

}  // namespace chimera::svt_detail
