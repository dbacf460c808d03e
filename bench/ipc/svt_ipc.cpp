// The latest value from one process to another through Chimera's global state variable table:
// the subscriber creates the table in POSIX shared memory, the publisher attaches to it by name,
// as a task in another process would. Keys: svt_ipc_latency_ns_p50, svt_ipc_latency_ns_p99.

#include <unistd.h>

#include <string>
#include <vector>

#include "chimera/svt/global_table.hpp"
#include "ipc/ipc_latency.hpp"

namespace chimera::bench {
namespace {

// The message travels as 8 words of one i64 variable: seq, two stamps and six doubles.
constexpr std::uint32_t kWords = sizeof(Message) / 8;
static_assert(sizeof(Message) % 8 == 0);

struct SvtSub {
  GlobalTable table;
  std::uint64_t seen = 0;
  bool take_latest(Message& m) {
    const ReadOutcome r = table.read(0, &m, seen);
    seen = r.version;
    return r.freshness == Freshness::kNew;
  }
};

struct SvtPub {
  GlobalTable table;
  bool ready() { return true; }  // the table exists before the publisher starts
  void publish(const Message& m) { table.write(0, &m); }
};

}  // namespace
}  // namespace chimera::bench

int main(int argc, char** argv) {
  using namespace chimera;
  using namespace chimera::bench;
  const Args args = Args::parse(argc, argv);
  const IpcPlan plan = plan_for(args);
  const std::string name = "bench_ipc_" + std::to_string(::getpid());
  IpcRun run = run_ipc_latency<SvtPub, SvtSub>(
      plan,
      [&]() -> std::unique_ptr<SvtPub> {
        auto t = GlobalTable::attach(name);
        if (!t) return nullptr;
        return std::make_unique<SvtPub>(SvtPub{std::move(*t)});
      },
      [&]() -> std::unique_ptr<SvtSub> {
        auto t = GlobalTable::create(name, std::vector<VarSpec>{{"latest", {ElemType::kI64, kWords}}});
        if (!t) {
          std::fprintf(stderr, "%s\n", t.error().message.c_str());
          return nullptr;
        }
        return std::make_unique<SvtSub>(SvtSub{std::move(*t), 0});
      });
  return report_ipc(args, "svt_ipc", "Chimera global table (POSIX shared memory, sequence protocol)", run, plan);
}
