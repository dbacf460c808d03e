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

// One dump for every task that entered ERROR since the last look, not one each: when many fail at
// once (a stall of the machine under thousands of hard tasks) a dump each wrote the same history
// over and over: 2,500 dumps of 5,000 tasks' rings held `chimera run` for more than ten minutes.
void Subsystem::Impl::dump_new_errors() {
  std::shared_lock<std::shared_mutex> runtime(runtime_mutex);  // an add replaces the tasks and the recorder
  if (!table || !recorder) return;
  events->collect(*tasks);  // so that last_failure is current
  std::vector<std::size_t> failed;
  for (std::size_t i = 0; i < tasks->size(); ++i) {
    if ((*tasks)[i].state() != TaskState::kError) continue;
    const TaskFailure failure = events->last_failure(i);
    if (failure.number == dumped_failure[i]) continue;
    dumped_failure[i] = failure.number;
    failed.push_back(i);
  }
  if (failed.empty()) return;
  const Task& first = (*tasks)[failed.front()];
  const TaskFailure failure = events->last_failure(failed.front());
  const std::size_t others = failed.size() - 1;
  const std::int64_t now = executive->now_ns();
  const std::string dir =
      fmt::format("{}/{}-{}{}-t{:.3f}s", options.error_dump_dir, spec.name, first.name(),
                  others == 0 ? std::string() : fmt::format("-and-{}-more", others),
                  static_cast<double>(failure.time_ns) / 1e9);
  std::string why = fmt::format("{} entered ERROR: {}", first.name(), failure.text);
  if (others != 0) {
    constexpr std::size_t kNamed = 20;
    std::string names;
    for (std::size_t n = 1; n < failed.size() && n <= kNamed; ++n)
      names += fmt::format("{}{}", n == 1 ? "" : ", ", (*tasks)[failed[n]].name());
    why += fmt::format("; and {} more with it: {}{}", others, names,
                       others > kNamed ? fmt::format(" and {} others", others - kNamed) : std::string());
  }
  const auto written = recorder->dump(dir, why, now, summary_lines(), write_subsystem_yaml(live_spec()));
  std::lock_guard<std::mutex> notes(notes_mutex);
  const std::string with = others == 0 ? std::string() : fmt::format(" ({} more tasks entered ERROR with it)", others);
  earlier_events.push_back(Event{now, first.name(),
                                 written ? fmt::format("flight recorder: the last {:.3g} s written to {}/{}",
                                                       recorder->seconds(), dir, with)
                                         : fmt::format("flight recorder: {}", written.error().message)});
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
