#pragma once
// --rt-check inside the executive: which task's real-time method runs on this thread now. A Task
// opens a scope around on(), cycle(), off() and sync() when the check is on; the allocator hook
// (chimera::rt_check::note_allocation) charges what happens meanwhile to that task. Private.

namespace chimera {

class Task;

/// Marks the calling thread as running a real-time method of `task` for the scope's lifetime;
/// restores what was marked before. Real-time safe: two thread-local stores.
class RtCheckScope {
 public:
  explicit RtCheckScope(Task& task) noexcept;
  ~RtCheckScope();
  RtCheckScope(const RtCheckScope&) = delete;
  RtCheckScope& operator=(const RtCheckScope&) = delete;
  RtCheckScope(RtCheckScope&&) = delete;
  RtCheckScope& operator=(RtCheckScope&&) = delete;

 private:
  Task* previous_;
};

}  // namespace chimera
