#include "chimera/net/event_feed.hpp"

#include <algorithm>
#include <utility>

#include <nlohmann/json.hpp>

namespace chimera::net {

namespace {

using nlohmann::json;

// Task names and texts come from files and modules: never let a stray byte make dump() throw.
std::string dump(const json& doc) { return doc.dump(-1, ' ', false, json::error_handler_t::replace); }

json state_or_null(const std::pair<std::string, TaskState>* task) {
  return task == nullptr ? json(nullptr) : json(state_name(task->second));
}

const std::pair<std::string, TaskState>* find(const std::vector<std::pair<std::string, TaskState>>& states,
                                              const std::string& name) {
  const auto it = std::find_if(states.begin(), states.end(), [&](const auto& s) { return s.first == name; });
  return it == states.end() ? nullptr : &*it;
}

json switch_json(const SwitchRecord& r) {
  return json{{"type", "switch"},
              {"t_ns", r.committed_ns},
              {"from", r.from},
              {"to", r.to},
              {"cause", r.cause},
              {"requested_ns", r.requested_ns},
              {"committed_ns", r.committed_ns},
              {"off", r.off},
              {"on", r.on},
              {"spawned", r.spawned},
              {"reinit", r.reinit},
              {"flag_raised", r.flag_raised}};
}

}  // namespace

void EventFeed::observe(const Subsystem& subsystem, const std::vector<Event>& events) {
  const std::int64_t now = subsystem.now_ns();
  auto states = subsystem.states();
  if (observed_) {
    // A task added (from null) or removed (to null) by the live assembly is a change too.
    for (const auto& task : states) {
      const auto* before = find(states_, task.first);
      if (before != nullptr && before->second == task.second) continue;
      publish(dump(json{{"type", "state"},
                        {"t_ns", now},
                        {"task", task.first},
                        {"from", state_or_null(before)},
                        {"to", state_name(task.second)}}));
    }
    for (const auto& task : states_)
      if (find(states, task.first) == nullptr)
        publish(dump(json{{"type", "state"},
                          {"t_ns", now},
                          {"task", task.first},
                          {"from", state_name(task.second)},
                          {"to", nullptr}}));
  }
  states_ = std::move(states);

  for (const auto& record : subsystem.switches(switches_seen_.load(std::memory_order_relaxed))) {
    publish(dump(switch_json(record)));
    switches_seen_.fetch_add(1, std::memory_order_relaxed);
  }

  const bool flag = subsystem.illegal_configuration();
  if (observed_ && flag != flag_) publish(dump(json{{"type", "flag"}, {"t_ns", now}, {"illegal_configuration", flag}}));
  flag_ = flag;
  observed_ = true;

  for (const auto& e : events)
    if (!e.is_switch)  // its record came above, as the switch event
      publish(dump(json{{"type", "log"}, {"t_ns", e.time_ns}, {"task", e.task}, {"text", e.text}}));
}

void EventFeed::publish(std::string text) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (ring_.size() < kCapacity) ring_.resize(kCapacity);
  Item& slot = ring_[next_ % kCapacity];
  slot.seq = next_++;
  slot.json = std::move(text);
}

std::uint64_t EventFeed::since(std::uint64_t from, std::size_t max, std::vector<Item>& out) const {
  out.clear();
  std::lock_guard<std::mutex> lock(mutex_);
  const std::uint64_t oldest = next_ > kCapacity ? next_ - kCapacity : 0;
  const std::uint64_t missed = from < oldest ? oldest - from : 0;
  for (std::uint64_t seq = std::max(from, oldest); seq < next_ && out.size() < max; ++seq)
    out.push_back(ring_[seq % kCapacity]);
  return missed;
}

std::uint64_t EventFeed::next_seq() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return next_;
}

}  // namespace chimera::net
