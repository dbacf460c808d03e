// A variable whose writer, in another process, is killed by SIGKILL in the middle of a write is
// still read whole (docs/processes.md, docs/state-variables.md): the table's slots guarantee it.
// Two ways: a child stopped half way through a write at a known point, and a child writing
// without pause that is killed wherever it happens to be, many times.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <string>

#include <gtest/gtest.h>

#include "chimera/svt/global_table.hpp"
#include "svt/global_table_test_access.hpp"

namespace chimera {
namespace {

constexpr std::uint32_t kWords = 64;  // 512 bytes: a write of many stores, easy to cut short
using Value = std::array<std::uint64_t, kWords>;

Value filled(std::uint64_t v) {
  Value out{};
  out.fill(v);
  return out;
}

// Whole: every word holds the same number (each write writes one number into all of them).
bool whole(const Value& v) {
  for (const std::uint64_t w : v)
    if (w != v[0]) return false;
  return true;
}

std::string table_name(const char* what) { return std::string("killed_writer_") + what + std::to_string(::getpid()); }

void wait_for(pid_t child) {
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;
}

TEST(KilledWriter, KilledHalfWayThroughAWriteLeavesTheLastCompleteValue) {
  const std::string name = table_name("half");
  const std::array<VarSpec, 1> vars{VarSpec{"x", {ElemType::kI64, kWords}}};
  auto table = GlobalTable::create(name, vars);
  ASSERT_TRUE(table) << table.error().message;
  const VarIndex x = *table->find("x");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // The writer, in a process of its own attached as a module process is: one whole value, then
    // half of the next, then death.
    auto mine = GlobalTable::attach(name);
    if (!mine) ::_exit(3);
    const Value first = filled(7);
    mine->write(x, first.data());
    const Value second = filled(8);
    GlobalTableTestAccess::begin_write(*mine, x);
    GlobalTableTestAccess::store_bytes(*mine, x, 0, second.data(), sizeof second / 2);
    ::kill(::getpid(), SIGKILL);
    ::_exit(4);
  }
  wait_for(child);
  Value read{};
  const ReadOutcome r = table->read(x, read.data(), 0);
  EXPECT_EQ(r.freshness, Freshness::kNew);
  EXPECT_EQ(read, filled(7));
  // A new writer (the process started again) goes on from there.
  const Value third = filled(9);
  table->write(x, third.data());
  EXPECT_EQ(table->read(x, read.data(), r.version).freshness, Freshness::kNew);
  EXPECT_EQ(read, filled(9));
}

TEST(KilledWriter, KilledAnywhereInAWriteLoopIsReadWhole) {
  const std::string name = table_name("loop");
  const std::array<VarSpec, 1> vars{VarSpec{"x", {ElemType::kI64, kWords}}};
  auto table = GlobalTable::create(name, vars);
  ASSERT_TRUE(table) << table.error().message;
  const VarIndex x = *table->find("x");
  for (int round = 0; round < 20; ++round) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      auto mine = GlobalTable::attach(name);
      if (!mine) ::_exit(3);
      for (std::uint64_t n = 1;; ++n) {
        const Value v = filled(n + static_cast<std::uint64_t>(round) * 1'000'000'000ULL);
        mine->write(x, v.data());
      }
    }
    // Wait until it has written (so the kill lands inside its loop), then kill it wherever it is.
    Value read{};
    while (table->read(x, read.data(), 0).freshness == Freshness::kNoData ||
           read[0] < static_cast<std::uint64_t>(round) * 1'000'000'000ULL + 1000) {
      ::usleep(100);
    }
    ::kill(child, SIGKILL);
    wait_for(child);
    const ReadOutcome r = table->read(x, read.data(), 0);
    ASSERT_EQ(r.freshness, Freshness::kNew) << "round " << round;
    EXPECT_TRUE(whole(read)) << "round " << round << ": a torn value";
  }
}

}  // namespace
}  // namespace chimera
