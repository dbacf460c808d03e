// The real-time path allocates nothing. This program replaces the allocator: while armed, every
// allocation is counted, and operator new fails by throwing. Cycles of the framework (transfers,
// statistics, timing, dispatch) and of the Figure 4 modules run armed, on both clocks.

#include <malloc.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/exec/subsystem.hpp"
#include "support/probe_module.hpp"

extern "C" {
void* __libc_malloc(std::size_t);                 // NOLINT: glibc's own allocator, which the hooks forward to
void* __libc_calloc(std::size_t, std::size_t);    // NOLINT: same
void* __libc_realloc(void*, std::size_t);         // NOLINT: same
void* __libc_memalign(std::size_t, std::size_t);  // NOLINT: same
void __libc_free(void*);                          // NOLINT: same
}

namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};

void note() {
  // relaxed: a flag and a counter read after the threads that count have been joined or parked
  if (g_armed.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(std::size_t n) {  // NOLINT: replaces the C allocator for this test program
  note();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t m) {  // NOLINT: same
  note();
  return __libc_calloc(n, m);
}
void* realloc(void* p, std::size_t n) {  // NOLINT: same
  note();
  return __libc_realloc(p, n);
}
void* memalign(std::size_t a, std::size_t n) {  // NOLINT: same
  note();
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) {  // NOLINT: same
  note();
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, std::size_t a, std::size_t n) {  // NOLINT: same
  note();
  *out = __libc_memalign(a, n);
  return *out ? 0 : ENOMEM;
}
void free(void* p) { __libc_free(p); }  // NOLINT: same
}

void* operator new(std::size_t n) {
  if (g_armed.load(std::memory_order_relaxed)) {  // relaxed: see note()
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    throw std::bad_alloc();
  }
  if (void* p = __libc_malloc(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __libc_free(p); }

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

struct Armed {
  Armed() {
    g_allocations.store(0);
    g_armed.store(true);
  }
  ~Armed() { g_armed.store(false); }
};

std::unique_ptr<Subsystem> fig4(ClockKind clock) {
  auto spec = load_subsystem_file(CHIMERA_EXAMPLES_DIR "/fig4_pid_joint.yaml", Registry::global());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  RunOptions o;
  o.clock = clock;
  o.shm_suffix = testing::unique_suffix();
  o.realtime_priorities = false;
  auto s = Subsystem::create(*spec, Registry::global(), o);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  EXPECT_TRUE((*s)->start().ok());
  return std::move(*s);
}

std::uint64_t total_cycles(const Subsystem& s) {
  std::uint64_t n = 0;
  for (const auto& t : s.snapshot()) n += t.stats.cycles;
  return n;
}

TEST(NoAllocationInCycle, Figure4OnTheVirtualClock) {
  auto s = fig4(ClockKind::kVirtual);
  s->run_for(100 * kMs);  // warm up: first touches, lazy initialisation
  const auto before = total_cycles(*s);
  {
    Armed armed;
    s->run_for(2000 * kMs);
  }
  EXPECT_EQ(g_allocations.load(), 0) << "allocations inside cycles";
  EXPECT_EQ(total_cycles(*s) - before, s->snapshot().size() * 2000u);
  for (const auto& t : s->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name;
}

TEST(NoAllocationInCycle, Figure4OnTheRealClock) {
  auto s = fig4(ClockKind::kReal);
  s->run_for(100 * kMs);
  const auto before = total_cycles(*s);
  {
    Armed armed;
    s->run_for(300 * kMs);  // every thread is counted, this one sleeps
  }
  EXPECT_EQ(g_allocations.load(), 0) << "allocations inside cycles";
  EXPECT_GT(total_cycles(*s), before + 300);
  for (const auto& t : s->snapshot()) EXPECT_EQ(t.state, TaskState::kOn) << t.name;
}

// The detector detects: a module that allocates in cycle() is caught, and its task goes to ERROR.
class Allocating : public Module {
 public:
  static constexpr const char* kName = "allocating";
  static constexpr const char* kSummary = "allocates in cycle";
  static constexpr const char* kDoc = "a bad module";
  static void declare(Declarations&, const Params&) {}

 protected:
  Status cycle() override {
    std::vector<double> v(64);
    return v.empty() ? Status::fail("impossible") : Status::ok();
  }
};

TEST(NoAllocationInCycle, AnAllocatingModuleIsCaught) {
  Registry reg;
  ASSERT_TRUE(reg.add(testing::info_of<Allocating>()).ok());
  auto spec = load_subsystem_text("subsystem: alloc\ntasks:\n  - {name: a, module: allocating, period: 1ms}\n",
                                  "alloc.yaml", reg);
  ASSERT_TRUE(spec.ok()) << spec.error().message;
  RunOptions o;
  o.clock = ClockKind::kVirtual;
  o.shm_suffix = testing::unique_suffix();
  auto s = Subsystem::create(*spec, reg, o);
  ASSERT_TRUE(s.ok());
  ASSERT_TRUE((*s)->start().ok());
  {
    Armed armed;
    (*s)->run_for(5 * kMs);
  }
  EXPECT_GT(g_allocations.load(), 0);
  EXPECT_EQ((*s)->snapshot()[0].state, TaskState::kError) << "the failed allocation is the module's fault";
}

}  // namespace
}  // namespace chimera
