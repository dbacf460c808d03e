#include "chimera/exec/rt_check.hpp"

#include "rt_check_scope.hpp"
#include "task.hpp"

namespace chimera {

namespace {
// The task whose real-time method runs on this thread, null outside those methods (and always
// without --rt-check). initial-exec: libchimera is loaded with the program, so this lives in the
// static TLS block; the general model may call malloc on a thread's first access, which would
// come straight back here from inside the allocator.
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): per-thread state by design
constinit thread_local Task* t_rt_task [[gnu::tls_model("initial-exec")]] = nullptr;
}  // namespace

RtCheckScope::RtCheckScope(Task& task) noexcept : previous_(t_rt_task) { t_rt_task = &task; }

RtCheckScope::~RtCheckScope() { t_rt_task = previous_; }

namespace rt_check {

void note_allocation() noexcept {
  Task* task = t_rt_task;
  if (task == nullptr) return;
  // Unmark while counting: whatever the count does must never be charged (or recurse) again.
  t_rt_task = nullptr;
  task->note_rt_allocation();
  t_rt_task = task;
}

}  // namespace rt_check

}  // namespace chimera
