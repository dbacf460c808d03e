// The data logger's ring of rows: order, wrap-around and what full means.

#include "data_logger/row_ring.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace chimera::modules {
namespace {

std::vector<double> drain_all(RowRing& ring) {
  std::vector<double> out;
  ring.drain([&](const double* row) { out.insert(out.end(), row, row + ring.width()); });
  return out;
}

bool push(RowRing& ring, double a, double b) {
  double* row = ring.claim();
  if (row == nullptr) return false;
  row[0] = a;
  row[1] = b;
  ring.publish();
  return true;
}

TEST(RowRing, RowsComeOutInOrder) {
  RowRing ring(4, 2);
  EXPECT_TRUE(drain_all(ring).empty());
  ASSERT_TRUE(push(ring, 1, 2));
  ASSERT_TRUE(push(ring, 3, 4));
  EXPECT_EQ(drain_all(ring), (std::vector<double>{1, 2, 3, 4}));
  EXPECT_TRUE(drain_all(ring).empty()) << "a row is read once";
}

TEST(RowRing, AFullRingRefusesUntilDrained) {
  RowRing ring(3, 2);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(push(ring, i, -i));
  EXPECT_EQ(ring.claim(), nullptr) << "three rows fill three slots";
  EXPECT_FALSE(push(ring, 9, 9));
  EXPECT_EQ(drain_all(ring), (std::vector<double>{0, 0, 1, -1, 2, -2})) << "the refused row left nothing";
  EXPECT_NE(ring.claim(), nullptr);
}

TEST(RowRing, WrapsAroundManyTimes) {
  RowRing ring(3, 2);
  for (int round = 0; round < 10; ++round) {
    ASSERT_TRUE(push(ring, round, 1));
    ASSERT_TRUE(push(ring, round, 2));
    EXPECT_EQ(drain_all(ring), (std::vector<double>{static_cast<double>(round), 1, static_cast<double>(round), 2}));
  }
}

TEST(RowRing, AClaimWithoutPublishIsNotSeen) {
  RowRing ring(2, 1);
  double* row = ring.claim();
  ASSERT_NE(row, nullptr);
  row[0] = 5;
  EXPECT_TRUE(drain_all(ring).empty());
  ring.publish();
  EXPECT_EQ(drain_all(ring), (std::vector<double>{5}));
}

}  // namespace
}  // namespace chimera::modules
