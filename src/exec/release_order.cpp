#include "release_order.hpp"

#include <algorithm>
#include <set>
#include <string>

namespace chimera {

namespace {
bool feeds(const ResolvedTask& producer, const ResolvedTask& consumer) {
  for (const auto& out : producer.bindings) {
    if (out.kind != PortKind::kOutVar) continue;
    for (const auto& in : consumer.bindings)
      if (in.kind == PortKind::kInVar && in.variable == out.variable) return true;
  }
  return false;
}
}  // namespace

ReleaseOrder compute_release_order(const ResolvedSubsystem& subsystem) {
  const auto& tasks = subsystem.tasks;
  const int n = static_cast<int>(tasks.size());
  ReleaseOrder order;
  order.rank.assign(static_cast<std::size_t>(n), 0);
  order.predecessors.assign(static_cast<std::size_t>(n), {});

  auto period = [&](int i) { return tasks[static_cast<std::size_t>(i)].spec->period_ns.value_or(-1); };
  std::set<long long> periods;
  for (int i = 0; i < n; ++i)
    if (period(i) > 0) periods.insert(period(i));

  for (const long long p : periods) {
    std::vector<int> group;
    for (int i = 0; i < n; ++i)
      if (period(i) == p) group.push_back(i);
    // Kahn's algorithm, taking the earliest task in the file among the ready ones; when only
    // cycles remain, the earliest task of the file goes next (the loop is cut before it).
    std::vector<int> placed;
    std::vector<bool> done(static_cast<std::size_t>(n), false);
    while (placed.size() < group.size()) {
      int pick = -1;
      for (const int c : group) {
        if (done[static_cast<std::size_t>(c)]) continue;
        bool ready = true;
        for (const int q : group)
          if (q != c && !done[static_cast<std::size_t>(q)] &&
              feeds(tasks[static_cast<std::size_t>(q)], tasks[static_cast<std::size_t>(c)]))
            ready = false;
        if (ready) {
          pick = c;
          break;
        }
      }
      if (pick < 0) {
        for (const int c : group)
          if (!done[static_cast<std::size_t>(c)]) {
            pick = c;
            break;
          }
      }
      done[static_cast<std::size_t>(pick)] = true;
      order.rank[static_cast<std::size_t>(pick)] = static_cast<int>(placed.size());
      placed.push_back(pick);
    }
    for (const int c : group)
      for (const int q : group)
        if (order.rank[static_cast<std::size_t>(q)] < order.rank[static_cast<std::size_t>(c)] &&
            feeds(tasks[static_cast<std::size_t>(q)], tasks[static_cast<std::size_t>(c)]))
          order.predecessors[static_cast<std::size_t>(c)].push_back(q);
  }
  return order;
}

}  // namespace chimera
