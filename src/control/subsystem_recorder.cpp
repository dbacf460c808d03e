// The subsystem interface's side of the flight recorder (docs/flight-recorder.md): the operator's
// dump, and the dump made when a task enters ERROR.

#include <fmt/format.h>

#include "chimera/config/spec_writer.hpp"
#include "subsystem_impl.hpp"

namespace chimera {

std::vector<std::string> Subsystem::Impl::summary_lines() const {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < tasks->size(); ++i) {
    if (is_removed(i)) continue;
    const Task& t = (*tasks)[i];
    const TaskFailure failure = events->last_failure(i);
    std::string line = fmt::format("{}: {}", t.name(), state_name(t.state()));
    if (failure.number != 0)
      line += fmt::format(" (last error at t = {} s: {})", static_cast<double>(failure.time_ns) / 1e9, failure.text);
    lines.push_back(std::move(line));
  }
  return lines;
}

void Subsystem::Impl::dump_new_errors() {
  std::shared_lock<std::shared_mutex> runtime(runtime_mutex);  // an add replaces the tasks and the recorder
  if (!table || !recorder) return;
  events->collect(*tasks);  // so that last_failure is current
  for (std::size_t i = 0; i < tasks->size(); ++i) {
    const Task& t = (*tasks)[i];
    if (t.state() != TaskState::kError) continue;
    const TaskFailure failure = events->last_failure(i);
    if (failure.number == dumped_failure[i]) continue;
    dumped_failure[i] = failure.number;
    const std::int64_t now = executive->now_ns();
    const std::string dir = fmt::format("{}/{}-{}-t{:.3f}s", options.error_dump_dir, spec.name, t.name(),
                                        static_cast<double>(failure.time_ns) / 1e9);
    const auto written = recorder->dump(dir, fmt::format("{} entered ERROR: {}", t.name(), failure.text), now,
                                        summary_lines(), write_subsystem_yaml(live_spec()));
    std::lock_guard<std::mutex> notes(notes_mutex);
    earlier_events.push_back(Event{now, t.name(),
                                   written ? fmt::format("flight recorder: the last {:.3g} s written to {}/",
                                                         recorder->seconds(), dir)
                                           : fmt::format("flight recorder: {}", written.error().message)});
  }
}

Result<std::string> Subsystem::dump(const std::string& dir, std::string_view why) const {
  const Impl& m = *impl_;
  std::shared_lock<std::shared_mutex> runtime(m.runtime_mutex);  // the table goes at stop
  if (m.table == nullptr) return make_error(Errc::kState, "the subsystem is stopped");
  if (!m.recorder) return make_error(Errc::kState, "dump: this run keeps no history (the flight recorder is off)");
  m.events->collect(*m.tasks);
  const std::int64_t now = m.executive->now_ns();
  const std::string where =
      !dir.empty() ? dir
                   : fmt::format("{}/{}-dump-t{:.3f}s", m.options.error_dump_dir.empty() ? "chimera-dumps" : m.options.error_dump_dir,
                                 m.spec.name, static_cast<double>(now) / 1e9);
  if (auto written = m.recorder->dump(where, std::string(why), now, m.summary_lines(), write_subsystem_yaml(m.live_spec())); !written) return written.error();
  return where;
}

double Subsystem::recorded_seconds() const {
  std::shared_lock<std::shared_mutex> runtime(impl_->runtime_mutex);
  return impl_->recorder ? impl_->recorder->seconds() : 0.0;
}

}  // namespace chimera
