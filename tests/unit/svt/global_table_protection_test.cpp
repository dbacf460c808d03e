// GlobalTable's page-per-variable placement and restrict_writes(): what a module process maps
// writable of the table (docs/processes.md). The protection is read back from the kernel's own
// account of the mapping (/proc/self/maps), so the test needs no fault to prove it.

#include <unistd.h>

#include <array>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/svt/detail/shm_layout.hpp"
#include "chimera/svt/global_table.hpp"
#include "unit/svt/svt_test_support.hpp"

namespace chimera {
namespace {

std::vector<VarSpec> vars() {
  return {{"theta_m", {ElemType::kF64, 6}}, {"tau_r", {ElemType::kF64, 6}}, {"jacobian", {ElemType::kF64, 36}}};
}

std::uint64_t page() { return static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)); }

// Bytes of this process's mappings of `subsystem`'s region with permissions `perms` ("r--s").
std::uint64_t mapped_bytes(const std::string& subsystem, const std::string& perms) {
  std::ifstream maps("/proc/self/maps");
  std::uint64_t total = 0;
  for (std::string line; std::getline(maps, line);) {
    if (line.find("/dev/shm/chimera_" + subsystem) == std::string::npos) continue;
    std::istringstream fields(line);
    std::string range;
    std::string p;
    fields >> range >> p;
    if (p != perms) continue;
    const auto dash = range.find('-');
    total += std::stoull(range.substr(dash + 1), nullptr, 16) - std::stoull(range.substr(0, dash), nullptr, 16);
  }
  return total;
}

TEST(GlobalTableProtection, APackedTableCannotBeRestricted) {
  const std::string name = test::unique_subsystem("packed");
  auto table = GlobalTable::create(name, vars());
  ASSERT_TRUE(table.ok()) << table.error().message;
  const std::array<VarIndex, 1> own{0};
  auto restricted = table->restrict_writes(own);
  ASSERT_FALSE(restricted.ok());
  EXPECT_NE(restricted.error().message.find("not laid out a page apart"), std::string::npos)
      << restricted.error().message;
}

// A page apart: the header alone on the first page, every block on pages of its own. Restricted to
// theta_m, a second mapping is writable on the header's page and theta_m's only; it still writes
// theta_m and raises the flag, and the owner reads both.
TEST(GlobalTableProtection, ARestrictedMappingWritesOnlyItsOwnVariablesAndTheFlag) {
  const std::string name = test::unique_subsystem("pages");
  auto owner = GlobalTable::create(name, vars(), GlobalTable::Placement::kPagePerVariable);
  ASSERT_TRUE(owner.ok()) << owner.error().message;
  EXPECT_EQ(owner->size() % page(), 0U);
  EXPECT_GE(owner->size(), 5 * page());  // header, directory, three blocks
  auto mine = GlobalTable::attach(name);
  ASSERT_TRUE(mine.ok()) << mine.error().message;
  const VarIndex theta_m = *mine->find("theta_m");
  const std::array<VarIndex, 1> own{theta_m};
  ASSERT_TRUE(mine->restrict_writes(own).ok());

  const std::uint64_t theta_m_pages = svt_detail::round_up(svt_detail::block_bytes(6), page());
  EXPECT_EQ(mapped_bytes(name, "r--s"), owner->size() - page() - theta_m_pages)
      << "every page but the header's and theta_m's is read-only in the restricted mapping";
  // The restricted mapping's two writable runs (the owner's mapping is of the file it made before
  // the file had its name, and is listed under another).
  EXPECT_EQ(mapped_bytes(name, "rw-s"), page() + theta_m_pages);

  const std::array<double, 6> value{1, 2, 3, 4, 5, 6};
  mine->write(theta_m, value.data());
  std::array<double, 6> seen{};
  EXPECT_EQ(owner->read(theta_m, seen.data(), 0).freshness, Freshness::kNew);
  EXPECT_EQ(seen, value);
  mine->raise_illegal_configuration();
  EXPECT_TRUE(owner->illegal_configuration());
  mine->lower_illegal_configuration();
  // What the restricted mapping reads of the others is the owner's.
  owner->write(*owner->find("tau_r"), value.data());
  std::array<double, 6> tau{};
  EXPECT_EQ(mine->read(*mine->find("tau_r"), tau.data(), 0).freshness, Freshness::kNew);
  EXPECT_EQ(tau, value);
}

}  // namespace
}  // namespace chimera
