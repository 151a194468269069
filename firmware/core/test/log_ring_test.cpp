#include "vibid/fw/log_ring.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>

namespace vibid::fw {
namespace {

// Records of 4 bytes holding their push number, little-endian.
std::array<std::uint8_t, 4> Rec(std::uint32_t n) {
  return {static_cast<std::uint8_t>(n), static_cast<std::uint8_t>(n >> 8),
          static_cast<std::uint8_t>(n >> 16), static_cast<std::uint8_t>(n >> 24)};
}

std::uint32_t ValueAt(const LogRing& ring, std::uint32_t index) {
  std::span<const std::uint8_t> r;
  if (ring.Read(index, r) != Status::kOk) return 0xFFFFFFFFu;
  return static_cast<std::uint32_t>(r[0] | r[1] << 8 | r[2] << 16 | r[3] << 24);
}

TEST(LogRing, CapacityAndResetRefusals) {
  std::array<std::uint8_t, 40> storage{};
  LogRing ring(storage);
  EXPECT_EQ(ring.CapacityFor(4), 10u);
  EXPECT_EQ(ring.CapacityFor(12), 3u);
  EXPECT_EQ(ring.Reset(0, 0), Status::kInvalidArgument);
  EXPECT_EQ(ring.Reset(4, 10), Status::kOutOfRange);
  EXPECT_EQ(ring.Reset(4, 9), Status::kOk);
  EXPECT_EQ(ring.capacity_records(), 10u);
}

// Pre-trigger pushes wrap the ring many times; at the trigger exactly the newest `pretrigger`
// records are kept, oldest first, and the first later push follows them.
TEST(LogRing, PreTriggerKeepsNewestAcrossWraps) {
  std::array<std::uint8_t, 40> storage{};
  LogRing ring(storage);
  ASSERT_EQ(ring.Reset(4, 6), Status::kOk);
  for (std::uint32_t n = 0; n < 37; ++n) EXPECT_TRUE(ring.Push(Rec(n)));
  EXPECT_FALSE(ring.triggered());
  EXPECT_EQ(ring.written(), 0u);
  ring.MarkTrigger();
  EXPECT_EQ(ring.trigger_index(), 6u);
  EXPECT_EQ(ring.written(), 6u);
  for (std::uint32_t i = 0; i < 6; ++i) EXPECT_EQ(ValueAt(ring, i), 31 + i);
  EXPECT_TRUE(ring.Push(Rec(37)));
  EXPECT_EQ(ValueAt(ring, 6), 37u);
}

// After the trigger nothing is overwritten: a full ring refuses, a release makes room, and
// indices stay continuous while the slots wrap.
TEST(LogRing, FullAfterTriggerRefusesUntilReleased) {
  std::array<std::uint8_t, 40> storage{};
  LogRing ring(storage);
  ASSERT_EQ(ring.Reset(4, 0), Status::kOk);
  ring.MarkTrigger();
  std::uint32_t n = 0;
  for (; n < 10; ++n) EXPECT_TRUE(ring.Push(Rec(n)));
  EXPECT_FALSE(ring.Push(Rec(999)));
  EXPECT_EQ(ring.written(), 10u);
  EXPECT_EQ(ring.Release(11), Status::kOutOfRange);
  ASSERT_EQ(ring.Release(4), Status::kOk);
  EXPECT_EQ(ring.Release(3), Status::kOutOfRange);  // cannot un-release
  for (std::uint32_t round = 0; round < 5; ++round) {
    for (std::uint32_t k = 0; k < 4; ++k, ++n) EXPECT_TRUE(ring.Push(Rec(n)));
    EXPECT_FALSE(ring.Push(Rec(999)));
    ASSERT_EQ(ring.Release(ring.released() + 4), Status::kOk);
  }
  for (std::uint32_t i = ring.released(); i < ring.written(); ++i) EXPECT_EQ(ValueAt(ring, i), i);
  std::span<const std::uint8_t> r;
  EXPECT_EQ(ring.Read(ring.released() - 1, r), Status::kOutOfRange);
  EXPECT_EQ(ring.Read(ring.written(), r), Status::kOutOfRange);
}

}  // namespace
}  // namespace vibid::fw
