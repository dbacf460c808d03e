#pragma once
// `chimera run --rt-check`: counts what a task's real-time methods (on, cycle, off, sync) do that
// the real-time path must not. The framework marks the thread while such a method runs (only when
// the check is on); a replacement allocator, which only a program that wants the check installs
// (the chimera command does, libchimera does not), reports each allocation here. So tests and
// users that bring their own allocator are untouched, and a run without the check pays nothing.

namespace chimera::rt_check {

/// Counts one allocation against the task whose real-time method runs on this thread, if any;
/// the first one caught also queues an event naming the task and the method. Meant to be called
/// from inside malloc or operator new: it allocates nothing, takes no lock, formats nothing and
/// never throws. Real-time safe, any thread.
void note_allocation() noexcept;

}  // namespace chimera::rt_check
