#include "ordinary_cpus.hpp"

#include <sched.h>
#include <sys/types.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace chimera::cli {

namespace {

bool is_realtime(int policy) { return policy == SCHED_FIFO || policy == SCHED_RR; }

// The ids of this process's threads, read from /proc/self/task.
std::vector<pid_t> threads_of_this_process() {
  std::vector<pid_t> tids;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    const std::string name = entry.path().filename().string();
    char* end = nullptr;
    const long tid = std::strtol(name.c_str(), &end, 10);
    if (end != name.c_str() && *end == '\0' && tid > 0) tids.push_back(static_cast<pid_t>(tid));
  }
  return tids;
}

}  // namespace

std::vector<int> ordinary_cpus(const std::vector<int>& realtime_cpus) {
  std::vector<int> free;
  if (realtime_cpus.empty()) return free;
  cpu_set_t usable;
  CPU_ZERO(&usable);
  if (sched_getaffinity(0, sizeof(usable), &usable) != 0) return free;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &usable) && std::find(realtime_cpus.begin(), realtime_cpus.end(), cpu) == realtime_cpus.end())
      free.push_back(cpu);
  return free;
}

bool keep_ordinary_threads_on(const std::vector<int>& cpus) {
  if (cpus.empty()) return false;
  const std::vector<pid_t> tids = threads_of_this_process();
  if (std::none_of(tids.begin(), tids.end(), [](pid_t tid) { return is_realtime(sched_getscheduler(tid)); }))
    return false;
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) CPU_SET(static_cast<unsigned>(cpu), &set);
  // A thread that ends meanwhile is no matter (ESRCH); one that starts meanwhile inherits its
  // creator's mask, and every creator is either moved here or a real-time task thread.
  for (const pid_t tid : tids)
    if (const int policy = sched_getscheduler(tid); policy >= 0 && !is_realtime(policy))
      (void)sched_setaffinity(tid, sizeof(set), &set);
  return true;
}

}  // namespace chimera::cli
