#include "chimera/analysis/release_order.hpp"

#include <algorithm>
#include <cstdint>
#include <map>
#include <numeric>
#include <set>
#include <string_view>

namespace chimera::analysis {

namespace {

/// Producer -> consumer edges among the tasks of one period group (indices into the file), each
/// once: a producer publishes an out-var the consumer reads as an in-var. Linear in the ports and
/// the edges, so that ten thousand tasks of one period cost milliseconds, not hours.
std::vector<std::vector<int>> consumers_of(const std::vector<ResolvedTask>& tasks, const std::vector<int>& group) {
  std::map<std::string_view, std::vector<int>> producers;  // variable -> its producers in the group
  for (const int i : group)
    for (const auto& b : tasks[static_cast<std::size_t>(i)].bindings)
      if (b.kind == PortKind::kOutVar) producers[b.variable].push_back(i);
  std::vector<std::vector<int>> out(tasks.size());
  for (const int c : group)
    for (const auto& b : tasks[static_cast<std::size_t>(c)].bindings) {
      if (b.kind != PortKind::kInVar) continue;
      const auto at = producers.find(b.variable);
      if (at == producers.end()) continue;
      for (const int p : at->second)
        if (p != c) out[static_cast<std::size_t>(p)].push_back(c);
    }
  for (auto& list : out) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return out;
}

/// The tasks of `group` in data-flow order: Kahn's algorithm taking the earliest task of the file
/// among the ready ones (no producer of the group left); when only loops remain, the earliest
/// remaining task of the file goes next (the loop is cut before it).
std::vector<int> data_flow_order(const std::vector<int>& group, const std::vector<std::vector<int>>& consumers) {
  std::vector<int> producers_left(consumers.size(), 0);
  for (const int p : group)
    for (const int c : consumers[static_cast<std::size_t>(p)]) ++producers_left[static_cast<std::size_t>(c)];
  std::set<int> left(group.begin(), group.end());
  std::set<int> ready;
  for (const int i : group)
    if (producers_left[static_cast<std::size_t>(i)] == 0) ready.insert(i);
  std::vector<int> order;
  order.reserve(group.size());
  while (!left.empty()) {
    const int pick = ready.empty() ? *left.begin() : *ready.begin();
    ready.erase(pick);
    left.erase(pick);
    order.push_back(pick);
    for (const int c : consumers[static_cast<std::size_t>(pick)])
      if (--producers_left[static_cast<std::size_t>(c)] == 0 && left.contains(c)) ready.insert(c);
  }
  return order;
}

/// Union-find's root of `i`, halving the path on the way.
int root(std::vector<int>& parent, int i) {
  const auto up = [&](int j) -> int& { return parent[static_cast<std::size_t>(j)]; };
  while (up(i) != i) {
    up(i) = up(up(i));
    i = up(i);
  }
  return i;
}

}  // namespace

ReleaseOrder compute_release_order(const ResolvedSubsystem& subsystem) {
  const auto& tasks = subsystem.tasks;
  const std::size_t n = tasks.size();
  ReleaseOrder result;
  result.rank.assign(n, 0);
  result.predecessors.assign(n, {});
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);

  std::map<std::int64_t, std::vector<int>> groups;  // period -> its tasks, in file order
  for (std::size_t i = 0; i < n; ++i)
    if (tasks[i].spec->period_ns) groups[*tasks[i].spec->period_ns].push_back(static_cast<int>(i));

  for (const auto& [period, group] : groups) {
    const auto consumers = consumers_of(tasks, group);
    const std::vector<int> order = data_flow_order(group, consumers);
    for (std::size_t r = 0; r < order.size(); ++r)
      result.rank[static_cast<std::size_t>(order[r])] = static_cast<int>(r);
    for (const int p : group)
      for (const int c : consumers[static_cast<std::size_t>(p)]) {
        // A task waits only for producers placed before it; a loop's back edge reads the last cycle.
        if (result.rank[static_cast<std::size_t>(p)] < result.rank[static_cast<std::size_t>(c)])
          result.predecessors[static_cast<std::size_t>(c)].push_back(p);
        // Chains take every edge, back edges included; the root stays at the smaller index, so that a
        // chain is named by its first task in the file.
        const int rp = root(parent, p);
        const int rc = root(parent, c);
        if (rp != rc) parent[static_cast<std::size_t>(std::max(rp, rc))] = std::min(rp, rc);
      }
  }
  for (auto& list : result.predecessors)  // in data-flow order, as the executives wait for them
    std::sort(list.begin(), list.end(), [&](int a, int b) {
      return result.rank[static_cast<std::size_t>(a)] < result.rank[static_cast<std::size_t>(b)];
    });
  result.chain.resize(n);
  for (std::size_t i = 0; i < n; ++i) result.chain[i] = root(parent, static_cast<int>(i));
  return result;
}

}  // namespace chimera::analysis
