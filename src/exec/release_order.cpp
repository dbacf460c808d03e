#include "release_order.hpp"

#include <cstdint>
#include <set>

namespace chimera {

namespace {

/// Whether `producer` publishes an out-var that `consumer` reads as an in-var.
bool feeds(const ResolvedTask& producer, const ResolvedTask& consumer) {
  for (const auto& out : producer.bindings) {
    if (out.kind != PortKind::kOutVar) continue;
    for (const auto& in : consumer.bindings)
      if (in.kind == PortKind::kInVar && in.variable == out.variable) return true;
  }
  return false;
}

/// Indices of the tasks of `group` in data-flow order: Kahn's algorithm taking the earliest task
/// of the file among the ready ones; when only cycles remain, the earliest remaining task of the
/// file goes next (the loop is cut before it).
std::vector<int> data_flow_order(const std::vector<ResolvedTask>& tasks, const std::vector<int>& group) {
  auto task = [&](int i) -> const ResolvedTask& { return tasks[static_cast<std::size_t>(i)]; };
  std::set<int> left(group.begin(), group.end());
  std::vector<int> order;
  while (!left.empty()) {
    int pick = *left.begin();  // the fallback that cuts a loop
    for (const int c : left) {
      bool ready = true;
      for (const int q : left) ready = ready && (q == c || !feeds(task(q), task(c)));
      if (ready) {
        pick = c;
        break;
      }
    }
    order.push_back(pick);
    left.erase(pick);
  }
  return order;
}

}  // namespace

ReleaseOrder compute_release_order(const ResolvedSubsystem& subsystem) {
  const auto& tasks = subsystem.tasks;
  const std::size_t n = tasks.size();
  ReleaseOrder result;
  result.rank.assign(n, 0);
  result.predecessors.assign(n, {});

  std::set<std::int64_t> periods;
  for (const auto& t : tasks)
    if (t.spec->period_ns) periods.insert(*t.spec->period_ns);

  for (const std::int64_t p : periods) {
    std::vector<int> group;  // in file order
    for (std::size_t i = 0; i < n; ++i)
      if (tasks[i].spec->period_ns == p) group.push_back(static_cast<int>(i));
    const std::vector<int> order = data_flow_order(tasks, group);
    for (std::size_t r = 0; r < order.size(); ++r)
      result.rank[static_cast<std::size_t>(order[r])] = static_cast<int>(r);
    // A task waits only for producers placed before it; a loop's back edge reads the last cycle.
    for (std::size_t r = 0; r < order.size(); ++r)
      for (std::size_t q = 0; q < r; ++q)
        if (feeds(tasks[static_cast<std::size_t>(order[q])], tasks[static_cast<std::size_t>(order[r])]))
          result.predecessors[static_cast<std::size_t>(order[r])].push_back(order[q]);
  }
  return result;
}

}  // namespace chimera
