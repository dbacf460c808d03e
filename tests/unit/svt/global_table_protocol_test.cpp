// GlobalTable's protocol on one thread: round trips of every element type and odd sizes, the
// freshness sequence, slot reuse, split writes, and the reader's steps against a lapping writer.
// The multi-threaded tests are in tests/stress/svt.

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/svt/detail/seq_protocol.hpp"
#include "chimera/svt/detail/shm_layout.hpp"
#include "chimera/svt/global_table.hpp"
#include "svt/global_table_test_access.hpp"
#include "unit/svt/svt_test_support.hpp"

namespace chimera {
namespace {

namespace d = svt_detail;
using test::unique_subsystem;

/// Bytes 1, 2, 3... shifted by `salt`, so two writes never look alike.
std::vector<std::byte> pattern(std::size_t bytes, int salt) {
  std::vector<std::byte> out(bytes);
  for (std::size_t i = 0; i < bytes; ++i) out[i] = static_cast<std::byte>((i * 7 + 1 + salt * 31) & 0xff);
  return out;
}

class ProtocolTest : public ::testing::Test {
 protected:
  void SetUp() override {
    vars_ = {{"f64x6", {ElemType::kF64, 6}},
             {"f32x3", {ElemType::kF32, 3}},
             {"i64x2", {ElemType::kI64, 2}},
             {"i32x5", {ElemType::kI32, 5}},
             {"u8x1", {ElemType::kU8, 1}},
             {"u8x13", {ElemType::kU8, 13}},
             {"f64x1024", {ElemType::kF64, 1024}},
             {"f64x2000", {ElemType::kF64, 2000}},
             // Every size that reads go through registers for (1 to 8 whole words), and the first after.
             {"f64x1", {ElemType::kF64, 1}},
             {"f64x2", {ElemType::kF64, 2}},
             {"f64x3", {ElemType::kF64, 3}},
             {"f64x4", {ElemType::kF64, 4}},
             {"f64x5", {ElemType::kF64, 5}},
             {"f64x7", {ElemType::kF64, 7}},
             {"f64x8", {ElemType::kF64, 8}},
             {"f64x9", {ElemType::kF64, 9}},
             {"u8x16", {ElemType::kU8, 16}}};
    auto t = GlobalTable::create(unique_subsystem("proto"), vars_);
    ASSERT_TRUE(t) << t.error().message;
    table_.emplace(std::move(*t));
  }
  GlobalTable& table() { return *table_; }
  VarIndex var(std::string_view name) { return *table_->find(name); }

  std::vector<VarSpec> vars_;
  std::optional<GlobalTable> table_;
};

TEST_F(ProtocolTest, EveryElementTypeAndSizeRoundTrips) {
  for (VarIndex v = 0; v < vars_.size(); ++v) {
    const std::size_t bytes = vars_[v].shape.bytes();
    for (int k = 1; k <= 6; ++k) {  // more writes than slots: every slot is used and reused
      const auto value = pattern(bytes, k);
      table().write(v, value.data());
      std::vector<std::byte> got(bytes);
      const ReadOutcome r = table().read(v, got.data(), static_cast<std::uint64_t>(k - 1));
      EXPECT_EQ(r.freshness, Freshness::kNew) << vars_[v].name;
      EXPECT_EQ(r.version, static_cast<std::uint64_t>(k)) << vars_[v].name;
      EXPECT_EQ(got, value) << vars_[v].name << " write " << k;
      EXPECT_EQ(table().version(v), static_cast<std::uint64_t>(k));
    }
  }
}

TEST_F(ProtocolTest, ReadsIntoUnalignedBytes) {
  for (VarIndex v = 0; v < vars_.size(); ++v) {
    const std::size_t bytes = vars_[v].shape.bytes();
    const auto value = pattern(bytes, 3);
    table().write(v, value.data());
    // One byte past an aligned start, with a guard byte either side that the read must not touch.
    std::vector<std::byte> buffer(bytes + 2, std::byte{0xA5});
    const ReadOutcome r = table().read(v, buffer.data() + 1, 0);
    EXPECT_EQ(r.freshness, Freshness::kNew) << vars_[v].name;
    EXPECT_TRUE(std::equal(value.begin(), value.end(), buffer.begin() + 1)) << vars_[v].name;
    EXPECT_EQ(buffer.front(), std::byte{0xA5}) << vars_[v].name;
    EXPECT_EQ(buffer.back(), std::byte{0xA5}) << vars_[v].name;
  }
}

TEST_F(ProtocolTest, TypedValuesSurvive) {
  const std::array<float, 3> f{1.5F, -2.25F, 3e30F};
  const std::array<std::int64_t, 2> i{INT64_MIN, INT64_MAX};
  const std::array<std::int32_t, 5> j{-1, 0, 1, INT32_MIN, INT32_MAX};
  table().write(var("f32x3"), f.data());
  table().write(var("i64x2"), i.data());
  table().write(var("i32x5"), j.data());
  std::array<float, 3> f2{};
  std::array<std::int64_t, 2> i2{};
  std::array<std::int32_t, 5> j2{};
  EXPECT_EQ(table().read(var("f32x3"), f2.data(), 0).freshness, Freshness::kNew);
  EXPECT_EQ(table().read(var("i64x2"), i2.data(), 0).freshness, Freshness::kNew);
  EXPECT_EQ(table().read(var("i32x5"), j2.data(), 0).freshness, Freshness::kNew);
  EXPECT_EQ(f2, f);
  EXPECT_EQ(i2, i);
  EXPECT_EQ(j2, j);
}

TEST_F(ProtocolTest, UnalignedSourceAndDestinationAndNoOverrun) {
  for (const char* name : {"u8x1", "f32x3", "u8x13", "f64x6", "f64x2000"}) {
    const VarIndex v = var(name);
    const std::size_t bytes = table().shape(v).bytes();
    // Source and destination at odd addresses; guard bytes after the destination must survive
    // the copy of the last, partial word.
    std::vector<std::byte> src(bytes + 1);
    const auto value = pattern(bytes, 5);
    std::memcpy(src.data() + 1, value.data(), bytes);
    table().write(v, src.data() + 1);
    std::vector<std::byte> dst(bytes + 9, std::byte{0xEE});
    EXPECT_EQ(table().read(v, dst.data() + 1, 0).freshness, Freshness::kNew) << name;
    EXPECT_EQ(std::memcmp(dst.data() + 1, value.data(), bytes), 0) << name;
    EXPECT_EQ(dst[0], std::byte{0xEE}) << name;
    for (std::size_t k = bytes + 1; k < dst.size(); ++k) EXPECT_EQ(dst[k], std::byte{0xEE}) << name << " byte " << k;
  }
}

TEST_F(ProtocolTest, FreshnessGoesNoDataNewOldNew) {
  const VarIndex v = var("f64x6");
  std::array<double, 6> dst{};
  dst.fill(-7);
  ReadOutcome r = table().read(v, dst.data(), 0);
  EXPECT_EQ(r.freshness, Freshness::kNoData);
  EXPECT_EQ(r.version, 0U);
  EXPECT_EQ(dst[0], -7);  // untouched

  const std::array<double, 6> a{1, 1, 1, 1, 1, 1};
  table().write(v, a.data());
  r = table().read(v, dst.data(), r.version);
  EXPECT_EQ(r.freshness, Freshness::kNew);
  EXPECT_EQ(r.version, 1U);
  EXPECT_EQ(dst, a);

  dst.fill(-7);  // an old read must not copy
  r = table().read(v, dst.data(), r.version);
  EXPECT_EQ(r.freshness, Freshness::kOld);
  EXPECT_EQ(r.version, 1U);
  EXPECT_EQ(dst[0], -7);

  const std::array<double, 6> b{2, 2, 2, 2, 2, 2};
  const std::array<double, 6> c{3, 3, 3, 3, 3, 3};
  table().write(v, b.data());
  table().write(v, c.data());
  r = table().read(v, dst.data(), r.version);
  EXPECT_EQ(r.freshness, Freshness::kNew);  // the newest, not the next
  EXPECT_EQ(r.version, 3U);
  EXPECT_EQ(dst, c);
}

TEST_F(ProtocolTest, SplitWriteIsInvisibleUntilItEnds) {
  const VarIndex v = var("u8x13");
  const auto a = pattern(13, 1);
  const auto b = pattern(13, 2);
  table().write(v, a.data());
  GlobalTableTestAccess::begin_write(table(), v);
  // Uneven pieces cross word boundaries: 0..3, 3..10, 10..13.
  GlobalTableTestAccess::store_bytes(table(), v, 0, b.data(), 3);
  GlobalTableTestAccess::store_bytes(table(), v, 3, b.data() + 3, 7);
  std::vector<std::byte> got(13);
  ReadOutcome r = table().read(v, got.data(), 0);
  EXPECT_EQ(r.freshness, Freshness::kNew);
  EXPECT_EQ(r.version, 1U);
  EXPECT_EQ(got, a);
  EXPECT_EQ(table().read(v, got.data(), 1).freshness, Freshness::kOld);
  GlobalTableTestAccess::store_bytes(table(), v, 10, b.data() + 10, 3);
  EXPECT_EQ(table().version(v), 1U);
  GlobalTableTestAccess::end_write(table(), v);
  r = table().read(v, got.data(), 1);
  EXPECT_EQ(r.freshness, Freshness::kNew);
  EXPECT_EQ(r.version, 2U);
  EXPECT_EQ(got, b);
}

// The reader's steps with a writer run between them, as a preempted reader would experience.
class LappingTest : public ProtocolTest {
 protected:
  void write_value(double k) {
    std::vector<double> value(6, k);
    table().write(v_, value.data());
  }
  void SetUp() override {
    ProtocolTest::SetUp();
    v_ = var("f64x6");
    // The block as a reader in another process sees it.
    raw_.emplace(table().shm_name().substr(std::string("/chimera_").size()));
    block_ = d::block_ref(raw_->base(), v_);
  }
  VarIndex v_ = 0;
  std::optional<test::RawMapping> raw_;
  d::BlockRef block_{};
};

TEST_F(LappingTest, FewerWritesThanSlotsDoNotDisturbAReader) {
  for (double k = 1; k <= 5; ++k) write_value(k);
  const std::uint64_t v = d::read_version(block_);
  ASSERT_EQ(v, 5U);
  const std::uint64_t s1 = d::read_open(block_, v);
  ASSERT_EQ(s1, 2 * v);
  for (double k = 6; k <= 8; ++k) write_value(k);  // kSlots - 1 writes: other slots
  std::array<std::uint64_t, 6> words{};
  d::read_copy(block_, v, words.data());
  EXPECT_TRUE(d::read_close(block_, v, s1));
  double first = 0;
  std::memcpy(&first, words.data(), 8);
  EXPECT_EQ(first, 5.0);
}

TEST_F(LappingTest, AWriterThatReusesTheSlotMidCopyIsDetected) {
  for (double k = 1; k <= 5; ++k) write_value(k);
  const std::uint64_t v = d::read_version(block_);
  const std::uint64_t s1 = d::read_open(block_, v);
  std::array<std::uint64_t, 6> words{};
  d::read_copy(block_, v, words.data());
  for (double k = 6; k <= 9; ++k) write_value(k);  // the fourth reuses slot v % kSlots
  EXPECT_FALSE(d::read_close(block_, v, s1));
}

TEST_F(LappingTest, AWriterStillInTheSlotIsDetected) {
  for (double k = 1; k <= 5; ++k) write_value(k);
  const std::uint64_t v = d::read_version(block_);
  const std::uint64_t s1 = d::read_open(block_, v);
  for (double k = 6; k <= 8; ++k) write_value(k);
  GlobalTableTestAccess::begin_write(table(), v_);  // write 9 starts on slot 9 % 4 == 5 % 4 and stops half way
  const std::array<double, 3> half{9, 9, 9};
  GlobalTableTestAccess::store_bytes(table(), v_, 0, half.data(), sizeof(half));
  std::array<std::uint64_t, 6> words{};
  d::read_copy(block_, v, words.data());
  EXPECT_FALSE(d::read_close(block_, v, s1));
  // A reader opening after the lap sees the slot is not write v's any more.
  EXPECT_NE(d::read_open(block_, v), 2 * v);
  GlobalTableTestAccess::store_bytes(table(), v_, sizeof(half), half.data(), sizeof(half));
  GlobalTableTestAccess::end_write(table(), v_);
  // The public read meanwhile always gets the newest whole value.
  std::array<double, 6> got{};
  const ReadOutcome r = table().read(v_, got.data(), 0);
  EXPECT_EQ(r.version, 9U);
  EXPECT_EQ(got, (std::array<double, 6>{9, 9, 9, 9, 9, 9}));
}

}  // namespace
}  // namespace chimera
