// GlobalTable's region: layout, lifetime (create, attach, removal, stale and live owners) and
// the directory. The protocol's round trips are in global_table_protocol_test.cpp.

#include "chimera/svt/global_table.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/svt/detail/shm_layout.hpp"
#include "unit/svt/svt_test_support.hpp"

namespace chimera {
namespace {

namespace d = svt_detail;
using test::RawMapping;
using test::unique_subsystem;

std::vector<VarSpec> fig4_vars() {
  return {{"theta_d", {ElemType::kF64, 6}},     {"theta_dot_d", {ElemType::kF64, 6}}, {"theta_m", {ElemType::kF64, 6}},
          {"theta_dot_m", {ElemType::kF64, 6}}, {"tau_r", {ElemType::kF64, 6}},       {"ndof", {ElemType::kI32, 1}},
          {"enabled", {ElemType::kU8, 1}},      {"image_row", {ElemType::kU8, 77}}};
}

std::string dev_shm_path(const std::string& subsystem) { return "/dev/shm/chimera_" + subsystem; }

bool exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

TEST(GlobalTableLayout, BlocksAndSlotsAreCacheLineAligned) {
  const auto name = unique_subsystem("layout");
  const auto vars = fig4_vars();
  auto table = GlobalTable::create(name, vars);
  ASSERT_TRUE(table) << table.error().message;
  EXPECT_EQ(table->shm_name(), "/chimera_" + name);

  // Walk the region through a second mapping, as another process would.
  RawMapping raw(name);
  ASSERT_NE(raw.base(), nullptr);
  ASSERT_EQ(raw.size(), table->size());
  const auto* header = d::object_at<d::Header>(raw.base(), 0);
  EXPECT_EQ(header->magic, d::kMagic);
  EXPECT_EQ(header->layout_version, d::kLayoutVersion);
  EXPECT_EQ(header->owner_pid, static_cast<std::uint64_t>(::getpid()));
  EXPECT_EQ(header->var_count, vars.size());
  EXPECT_EQ(header->total_size, raw.size());
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(&header->illegal_configuration) % d::kCacheLine, 0U);

  std::uint64_t previous_end = header->directory_offset + vars.size() * sizeof(d::DirEntry);
  for (VarIndex v = 0; v < vars.size(); ++v) {
    const d::DirEntry* e = d::dir_entry(raw.base(), v);
    EXPECT_STREQ(e->name.data(), vars[v].name.c_str());
    EXPECT_EQ(e->block_offset % d::kCacheLine, 0U) << vars[v].name;
    EXPECT_GE(e->block_offset, previous_end) << "blocks overlap at " << vars[v].name;
    EXPECT_EQ(e->payload_words, (vars[v].shape.bytes() + 7) / 8);
    previous_end = e->block_offset + d::block_bytes(e->payload_words);
    const d::BlockRef b = d::block_ref(raw.base(), v);
    // The version and every slot start a cache line of their own.
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(b.version) % d::kCacheLine, 0U);
    for (std::uint64_t s = 0; s < d::kSlots; ++s) {
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(b.seq(s)) % d::kCacheLine, 0U);
      EXPECT_GE(reinterpret_cast<std::byte*>(b.seq(s)), reinterpret_cast<std::byte*>(b.version) + d::kCacheLine);
    }
  }
  EXPECT_LE(previous_end, header->total_size);
}

TEST(GlobalTableLayout, DirectoryAnswersNamesAndShapes) {
  const auto vars = fig4_vars();
  auto table = GlobalTable::create(unique_subsystem("dir"), vars);
  ASSERT_TRUE(table) << table.error().message;
  for (VarIndex v = 0; v < vars.size(); ++v) {
    EXPECT_EQ(table->name(v), vars[v].name);
    EXPECT_EQ(table->shape(v), vars[v].shape);
    EXPECT_EQ(table->find(vars[v].name), v);
    EXPECT_EQ(table->version(v), 0U);
  }
  EXPECT_FALSE(table->find("theta"));
  EXPECT_FALSE(table->find("theta_d_"));
  EXPECT_FALSE(table->find(""));
}

TEST(GlobalTableLifetime, AttachSeesTheSameVariablesAndValues) {
  const auto name = unique_subsystem("attach");
  const auto vars = fig4_vars();
  auto owner = GlobalTable::create(name, vars);
  ASSERT_TRUE(owner) << owner.error().message;
  const std::array<double, 6> q{1, 2, 3, 4, 5, 6};
  owner->write(*owner->find("theta_m"), q.data());

  auto other = GlobalTable::attach(name);
  ASSERT_TRUE(other) << other.error().message;
  EXPECT_EQ(other->size(), owner->size());
  for (VarIndex v = 0; v < vars.size(); ++v) {
    EXPECT_EQ(other->name(v), vars[v].name);
    EXPECT_EQ(other->shape(v), vars[v].shape);
  }
  std::array<double, 6> got{};
  const ReadOutcome r = other->read(*other->find("theta_m"), got.data(), 0);
  EXPECT_EQ(r.freshness, Freshness::kNew);
  EXPECT_EQ(r.version, 1U);
  EXPECT_EQ(got, q);

  // And the other way round: a write through the attached handle reaches the owner.
  const std::array<double, 6> tau{-1, -2, -3, -4, -5, -6};
  other->write(*other->find("tau_r"), tau.data());
  EXPECT_EQ(owner->read(*owner->find("tau_r"), got.data(), 0).freshness, Freshness::kNew);
  EXPECT_EQ(got, tau);

  // Detaching does not remove the region; only the owner does.
  {
    auto third = GlobalTable::attach(name);
    ASSERT_TRUE(third) << third.error().message;
  }
  EXPECT_TRUE(exists(dev_shm_path(name)));
  EXPECT_EQ(owner->version(*owner->find("theta_m")), 1U);
}

TEST(GlobalTableLifetime, RegionHasMode0600WhateverTheUmask) {
  const auto name = unique_subsystem("mode");
  const mode_t old_umask = ::umask(0);  // shm_open would otherwise create 0600 by luck of umask 022
  auto table = GlobalTable::create(name, fig4_vars());
  ::umask(old_umask);
  ASSERT_TRUE(table) << table.error().message;
  struct stat st {};
  ASSERT_EQ(::stat(dev_shm_path(name).c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600U);
  EXPECT_EQ(st.st_uid, ::getuid());
}

TEST(GlobalTableLifetime, RegionIsRemovedWhenTheOwnerIsDestroyed) {
  const auto name = unique_subsystem("remove");
  {
    auto table = GlobalTable::create(name, fig4_vars());
    ASSERT_TRUE(table) << table.error().message;
    EXPECT_TRUE(exists(dev_shm_path(name)));
    // Moving the owner moves the duty to remove; the moved-from handle does nothing.
    GlobalTable moved = std::move(*table);
    EXPECT_TRUE(exists(dev_shm_path(name)));
  }
  EXPECT_FALSE(exists(dev_shm_path(name)));
  auto again = GlobalTable::attach(name);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.error().code, Errc::kNotFound);
  EXPECT_NE(again.error().message.find("is not running"), std::string::npos) << again.error().message;
}

TEST(GlobalTableLifetime, MoveAssignmentReleasesTheOldRegion) {
  const auto first = unique_subsystem("assign");
  const auto second = unique_subsystem("assign");
  auto a = GlobalTable::create(first, fig4_vars());
  auto b = GlobalTable::create(second, fig4_vars());
  ASSERT_TRUE(a && b);
  *a = std::move(*b);
  EXPECT_FALSE(exists(dev_shm_path(first)));
  EXPECT_TRUE(exists(dev_shm_path(second)));
  EXPECT_EQ(a->shm_name(), "/chimera_" + second);
}

TEST(GlobalTableLifetime, StaleRegionOfADeadProcessIsReplaced) {
  const auto name = unique_subsystem("stale");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // The child creates the region and dies without its destructor: a crash, as far as the
    // region can tell.
    auto table = GlobalTable::create(name, fig4_vars());
    ::_exit(table ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);  // reaped: kill(child, 0) now fails with ESRCH
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  ASSERT_TRUE(exists(dev_shm_path(name)));

  const std::vector<VarSpec> vars{{"x", {ElemType::kF64, 2}}};
  auto table = GlobalTable::create(name, vars);
  ASSERT_TRUE(table) << table.error().message;
  EXPECT_EQ(table->find("x"), 0U);
  EXPECT_FALSE(table->find("theta_d"));  // the stale layout is gone
  RawMapping raw(name);
  EXPECT_EQ(d::object_at<d::Header>(raw.base(), 0)->owner_pid, static_cast<std::uint64_t>(::getpid()));
}

TEST(GlobalTableLifetime, AStaleRegionIsReplacedWhateverBecameOfItsPid) {
  // Liveness is the creator's lock, not its pid: a dead creator's region is stale even when its
  // pid now belongs to a live process (this one, or init).
  for (const pid_t recorded : {::getpid(), pid_t{1}}) {
    const auto name = unique_subsystem("reused");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      auto table = GlobalTable::create(name, fig4_vars());
      ::_exit(table ? 0 : 1);  // no destructor: the region stays, its lock goes with the process
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    {
      RawMapping raw(name);
      ASSERT_NE(raw.base(), nullptr);
      d::object_at<d::Header>(raw.base(), 0)->owner_pid = static_cast<std::uint64_t>(recorded);
    }
    auto table = GlobalTable::create(name, fig4_vars());
    ASSERT_TRUE(table) << "pid " << recorded << ": " << table.error().message;
    RawMapping raw(name);
    EXPECT_EQ(d::object_at<d::Header>(raw.base(), 0)->owner_pid, static_cast<std::uint64_t>(::getpid()));
  }
}

TEST(GlobalTableLifetime, ReclaimStaleRemovesTheDeadOnesOfAPrefixOnly) {
  // Two regions left by a dead process under the prefix, one live region under it, and one left
  // by the dead process under another name.
  const auto prefix = unique_subsystem("sweep") + "_measure_";
  const auto other = unique_subsystem("unswept");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto a = GlobalTable::create(prefix + "1_0", fig4_vars());
    auto b = GlobalTable::create(prefix + "1_1", fig4_vars());
    auto c = GlobalTable::create(other, fig4_vars());
    ::_exit(a && b && c ? 0 : 1);  // no destructors: the regions stay, their locks go
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  auto live = GlobalTable::create(prefix + "2_0", fig4_vars());
  ASSERT_TRUE(live) << live.error().message;

  EXPECT_EQ(GlobalTable::reclaim_stale(prefix), 2U);
  EXPECT_FALSE(exists(dev_shm_path(prefix + "1_0")));
  EXPECT_FALSE(exists(dev_shm_path(prefix + "1_1")));
  EXPECT_TRUE(exists(dev_shm_path(prefix + "2_0"))) << "a live region is left";
  EXPECT_TRUE(exists(dev_shm_path(other))) << "another prefix is left";
  EXPECT_EQ(GlobalTable::reclaim_stale(prefix), 0U);
  EXPECT_EQ(GlobalTable::reclaim_stale(other), 1U);
}

TEST(GlobalTableLifetime, TheSignalTimeRemovalTakesOnlyThisProcesssOwnNames) {
  const auto name = unique_subsystem("abrupt");
  auto old_owner = GlobalTable::create(name, fig4_vars());
  ASSERT_TRUE(old_owner) << old_owner.error().message;
  GlobalTable::remove_owned_names_now();
  EXPECT_FALSE(exists(dev_shm_path(name)));
  // The mapping stays usable; the name is free for a new region, which the old owner's release
  // must then leave alone.
  const std::vector<std::byte> value(old_owner->shape(0).bytes(), std::byte{1});
  old_owner->write(0, value.data());
  EXPECT_EQ(old_owner->version(0), 1U);
  {
    auto newer = GlobalTable::create(name, fig4_vars());
    ASSERT_TRUE(newer) << newer.error().message;
    *old_owner = GlobalTable::create(unique_subsystem("other"), fig4_vars()).value();  // releases the old region
    EXPECT_TRUE(exists(dev_shm_path(name))) << "the old owner removed the newer region's name";
  }
  EXPECT_FALSE(exists(dev_shm_path(name)));
}

TEST(GlobalTableLifetime, RegionWithoutOwnerIsReplacedAfterAWait) {
  // A creator that died between shm_open and storing its pid leaves a region of zeros.
  const auto name = unique_subsystem("ownerless");
  const std::string shm = "/chimera_" + name;
  const int fd = ::shm_open(shm.c_str(), O_CREAT | O_EXCL | O_RDWR, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, 4096), 0);
  ::close(fd);

  auto attached = GlobalTable::attach(name);
  ASSERT_FALSE(attached);
  EXPECT_NE(attached.error().message.find("is not a state variable table"), std::string::npos)
      << attached.error().message;

  auto table = GlobalTable::create(name, fig4_vars());
  ASSERT_TRUE(table) << table.error().message;
  EXPECT_TRUE(GlobalTable::attach(name));
}

TEST(GlobalTableLifetime, LiveOwnerIsRefused) {
  const auto name = unique_subsystem("live");
  auto first = GlobalTable::create(name, fig4_vars());
  ASSERT_TRUE(first) << first.error().message;
  auto second = GlobalTable::create(name, fig4_vars());
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error().code, Errc::kSystem);
  const std::string expected = "subsystem '" + name + "' is already running (pid " + std::to_string(::getpid()) +
                               "); shared memory /chimera_" + name;
  EXPECT_EQ(second.error().message, expected);
  // The refused attempt left the running table alone.
  const std::vector<std::byte> value(first->shape(0).bytes(), std::byte{1});  // the variable's whole size
  first->write(0, value.data());
  EXPECT_TRUE(exists(dev_shm_path(name)));
  EXPECT_EQ(first->version(0), 1U);
}

TEST(GlobalTableLifetime, AttachRefusesAnotherLayoutVersion) {
  const auto name = unique_subsystem("version");
  auto table = GlobalTable::create(name, fig4_vars());
  ASSERT_TRUE(table) << table.error().message;
  RawMapping raw(name);
  auto* header = d::object_at<d::Header>(raw.base(), 0);
  header->layout_version = d::kLayoutVersion + 1;
  auto attached = GlobalTable::attach(name);
  ASSERT_FALSE(attached);
  EXPECT_NE(attached.error().message.find("another version of Chimera"), std::string::npos) << attached.error().message;
  header->layout_version = d::kLayoutVersion;
  EXPECT_TRUE(GlobalTable::attach(name));
  // The same version word but another shape behind it (a build whose header differs only where
  // the version was not bumped): the fingerprint tells them apart.
  header->layout_fingerprint = d::kLayoutFingerprint ^ 1U;
  EXPECT_FALSE(GlobalTable::attach(name));
  header->layout_fingerprint = d::kLayoutFingerprint;
  EXPECT_TRUE(GlobalTable::attach(name));
}

TEST(GlobalTableLayout, TheFingerprintChangesWithEveryIngredient) {
  // The version is computed from the shape, never kept in step by hand: any constant, size or
  // offset that enters it moves it.
  const std::uint64_t base = d::fingerprint({d::kSlots, d::kCacheLine, sizeof(d::Header), sizeof(d::DirEntry)});
  EXPECT_NE(base, d::fingerprint({d::kSlots + 1, d::kCacheLine, sizeof(d::Header), sizeof(d::DirEntry)}));
  EXPECT_NE(base, d::fingerprint({d::kSlots, d::kCacheLine, sizeof(d::Header) + 8, sizeof(d::DirEntry)}));
  EXPECT_NE(base, d::fingerprint({d::kSlots, d::kCacheLine, sizeof(d::Header), sizeof(d::DirEntry) + 8}));
  EXPECT_NE(base, d::fingerprint({d::kCacheLine, d::kSlots, sizeof(d::Header), sizeof(d::DirEntry)}))
      << "order matters";
  EXPECT_EQ(d::kLayoutVersion, static_cast<std::uint32_t>(d::kLayoutFingerprint ^ (d::kLayoutFingerprint >> 32U)));
}

TEST(GlobalTableLifetime, AttachRefusesADamagedDirectory) {
  const auto name = unique_subsystem("damaged");
  auto table = GlobalTable::create(name, fig4_vars());
  ASSERT_TRUE(table) << table.error().message;
  RawMapping raw(name);
  auto* e = const_cast<d::DirEntry*>(d::dir_entry(raw.base(), 3));
  const std::uint64_t saved = e->block_offset;
  e->block_offset = raw.size();  // past the end
  auto attached = GlobalTable::attach(name);
  ASSERT_FALSE(attached);
  EXPECT_NE(attached.error().message.find("damaged"), std::string::npos) << attached.error().message;
  e->block_offset = saved;
}

TEST(GlobalTableLifetime, RejectsBadNamesAndShapes) {
  const auto name = unique_subsystem("bad");
  auto expect_invalid = [&](std::string_view subsystem, std::vector<VarSpec> vars, std::string_view words) {
    auto t = GlobalTable::create(subsystem, vars);
    ASSERT_FALSE(t);
    EXPECT_EQ(t.error().code, Errc::kInvalidInput);
    EXPECT_NE(t.error().message.find(words), std::string::npos) << t.error().message;
  };
  expect_invalid("a/b", {}, "subsystem name");
  expect_invalid("", {}, "subsystem name");
  expect_invalid(name, {{"x", {ElemType::kF64, 1}}, {"x", {ElemType::kF64, 2}}}, "'x' is declared twice");
  expect_invalid(name, {{"", {ElemType::kF64, 1}}}, "must have 1 to 63 characters");
  expect_invalid(name, {{std::string(64, 'a'), {ElemType::kF64, 1}}}, "must have 1 to 63 characters");
  expect_invalid(name, {{"empty", {ElemType::kF64, 0}}}, "'empty' has no elements");
  EXPECT_FALSE(exists(dev_shm_path(name)));
  // 63 characters is the longest name that fits with its terminator.
  const std::vector<VarSpec> longest{{std::string(63, 'a'), {ElemType::kU8, 1}}};
  auto ok = GlobalTable::create(name, longest);
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->find(std::string(63, 'a')), 0U);
}

TEST(GlobalTableLifetime, EmptyTableIsValid) {
  const auto name = unique_subsystem("empty");
  auto table = GlobalTable::create(name, std::span<const VarSpec>{});
  ASSERT_TRUE(table) << table.error().message;
  EXPECT_FALSE(table->find("x"));
  EXPECT_TRUE(GlobalTable::attach(name));
}

TEST(GlobalTableFlag, IllegalConfigurationIsSharedThroughTheRegion) {
  const auto name = unique_subsystem("flag");
  auto owner = GlobalTable::create(name, fig4_vars());
  ASSERT_TRUE(owner) << owner.error().message;
  auto other = GlobalTable::attach(name);
  ASSERT_TRUE(other) << other.error().message;
  EXPECT_FALSE(owner->illegal_configuration());
  other->raise_illegal_configuration();
  EXPECT_TRUE(owner->illegal_configuration());
  EXPECT_TRUE(other->illegal_configuration());
  owner->raise_illegal_configuration();
  EXPECT_EQ(other->illegal_configuration_holds(), 2U);
  other->lower_illegal_configuration();
  EXPECT_TRUE(owner->illegal_configuration()) << "one hold is left: the flag stays up";
  owner->lower_illegal_configuration();
  EXPECT_FALSE(other->illegal_configuration());
}

TEST(GlobalTableFlag, RaisersAndLowerersOnManyThreadsNeverLoseAHold) {
  // Each thread raises and lowers in turn; one more hold is kept throughout. Whatever the
  // interleaving, the flag never reads down while that hold lasts, and reads down at the end.
  const auto name = unique_subsystem("flagrace");
  auto table = GlobalTable::create(name, fig4_vars());
  ASSERT_TRUE(table) << table.error().message;
  table->raise_illegal_configuration();
  std::atomic<bool> ever_down{false};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < 20'000; ++i) {
        table->raise_illegal_configuration();
        if (!table->illegal_configuration()) ever_down.store(true, std::memory_order_relaxed);  // a verdict only
        table->lower_illegal_configuration();
        if (!table->illegal_configuration()) ever_down.store(true, std::memory_order_relaxed);  // as above
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_FALSE(ever_down.load());
  EXPECT_EQ(table->illegal_configuration_holds(), 1U);
  table->lower_illegal_configuration();
  EXPECT_FALSE(table->illegal_configuration());
}

TEST(GlobalTableFlagDeathTest, LoweringWithoutAHoldIsABrokenInvariant) {
  const auto name = unique_subsystem("flagunder");
  auto table = GlobalTable::create(name, fig4_vars());
  ASSERT_TRUE(table) << table.error().message;
  EXPECT_DEATH(table->lower_illegal_configuration(), "invariant broken: the illegal-configuration flag lowered");
}

}  // namespace
}  // namespace chimera
