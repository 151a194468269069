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

// Room for ten records, triggered before the first: every record pushed is kept until released.
struct TriggeredRing {
  TriggeredRing() {
    EXPECT_EQ(ring.Reset(4, 0), Status::kOk);
    ring.MarkTrigger();
  }
  std::array<std::uint8_t, 40> storage{};
  LogRing ring{storage};
};

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
  TriggeredRing t;
  LogRing& ring = t.ring;
  std::uint32_t n = 0;
  for (; n < 10; ++n) EXPECT_TRUE(ring.Push(Rec(n)));
  EXPECT_FALSE(ring.Push(Rec(999)));
  EXPECT_EQ(ring.written(), 10u);
  EXPECT_EQ(ring.Release(11), Status::kOutOfRange);
  ASSERT_EQ(ring.Release(4), Status::kOk);
  for (std::uint32_t round = 0; round < 5; ++round) {
    for (std::uint32_t k = 0; k < 4; ++k, ++n) EXPECT_TRUE(ring.Push(Rec(n)));
    EXPECT_FALSE(ring.Push(Rec(999)));
    ASSERT_EQ(ring.Release(ring.released() + 4), Status::kOk);
  }
  for (std::uint32_t i = ring.released(); i < ring.written(); ++i) EXPECT_EQ(ValueAt(ring, i), i);
  // 30 written into 10 slots, 24 released: index 30 may already be going into record 20's
  // slot, so 21 is the oldest record still intact.
  std::span<const std::uint8_t> r;
  EXPECT_EQ(ring.written(), 30u);
  EXPECT_EQ(ring.released(), 24u);
  EXPECT_EQ(ring.oldest(), 21u);
  EXPECT_EQ(ring.Read(20, r), Status::kOutOfRange);
  EXPECT_EQ(ValueAt(ring, 21), 21u);
  EXPECT_EQ(ring.Read(ring.written(), r), Status::kOutOfRange);
}

// A release only lets the producer reuse slots: released records read back unchanged until the
// producer writes over them, and the oldest readable index follows the overwrites.
TEST(LogRing, ReleasedRecordsStayReadableUntilOverwritten) {
  TriggeredRing t;
  LogRing& ring = t.ring;
  for (std::uint32_t n = 0; n < 8; ++n) ASSERT_TRUE(ring.Push(Rec(n)));
  ASSERT_EQ(ring.Release(8), Status::kOk);  // a host pulled everything while sampling
  EXPECT_EQ(ring.released(), 8u);
  EXPECT_EQ(ring.oldest(), 0u);
  for (std::uint32_t i = 0; i < 8; ++i) EXPECT_EQ(ValueAt(ring, i), i);

  // Index 10 took slot 0, and index 11 may be going into slot 1 from now on: records 0 and 1
  // are gone as far as a reader can tell, 2..10 are there.
  for (std::uint32_t n = 8; n < 11; ++n) ASSERT_TRUE(ring.Push(Rec(n)));
  EXPECT_EQ(ring.oldest(), 2u);
  EXPECT_FALSE(ring.Intact(0));
  EXPECT_FALSE(ring.Intact(1));
  EXPECT_EQ(ValueAt(ring, 1), 0xFFFFFFFFu);
  for (std::uint32_t i = 2; i < 11; ++i) EXPECT_EQ(ValueAt(ring, i), i);

  // Each push takes one more.
  EXPECT_TRUE(ring.Intact(2));
  ASSERT_TRUE(ring.Push(Rec(11)));
  EXPECT_FALSE(ring.Intact(2));
  EXPECT_TRUE(ring.Intact(3));
  EXPECT_EQ(ring.oldest(), 3u);
}

// Release never moves back; a release beyond the log is refused and changes nothing.
TEST(LogRing, ReleaseIsMonotonic) {
  TriggeredRing t;
  LogRing& ring = t.ring;
  for (std::uint32_t n = 0; n < 6; ++n) ASSERT_TRUE(ring.Push(Rec(n)));
  ASSERT_EQ(ring.Release(5), Status::kOk);
  EXPECT_EQ(ring.Release(2), Status::kOk);  // a re-read from 2 does not take space back
  EXPECT_EQ(ring.released(), 5u);
  EXPECT_EQ(ring.Release(7), Status::kOutOfRange);
  EXPECT_EQ(ring.released(), 5u);
  EXPECT_EQ(ring.Release(6), Status::kOk);
  EXPECT_EQ(ring.released(), 6u);
  // Room for exactly 6 more (capacity 10, 4 unreleased slots free plus 6 released ones).
  for (std::uint32_t n = 6; n < 16; ++n) EXPECT_TRUE(ring.Push(Rec(n)));
  EXPECT_FALSE(ring.Push(Rec(16)));
}

// An unreleased record is never overwritten, even when the full ring makes written() reach
// index + capacity: the producer drops instead, so the whole log stays readable from 0.
TEST(LogRing, FullRingWithoutReleaseKeepsIndexZero) {
  TriggeredRing t;
  LogRing& ring = t.ring;
  for (std::uint32_t n = 0; n < 10; ++n) ASSERT_TRUE(ring.Push(Rec(n)));
  EXPECT_FALSE(ring.Push(Rec(10)));
  EXPECT_EQ(ring.oldest(), 0u);
  EXPECT_TRUE(ring.Intact(0));
  EXPECT_EQ(ValueAt(ring, 0), 0u);
}

// The reader's re-check after a copy: a record copied, then overwritten by the producer before
// the check, is reported as no longer intact, and the copy indeed differs from the record.
TEST(LogRing, RecheckAfterCopyDetectsAnOverwrite) {
  TriggeredRing t;
  LogRing& ring = t.ring;
  for (std::uint32_t n = 0; n < 9; ++n) ASSERT_TRUE(ring.Push(Rec(n)));
  ASSERT_EQ(ring.Release(9), Status::kOk);

  std::span<const std::uint8_t> view;
  ASSERT_EQ(ring.Read(0, view), Status::kOk);
  std::array<std::uint8_t, 4> copy{};
  std::copy(view.begin(), view.end(), copy.begin());
  EXPECT_TRUE(ring.Intact(0));  // nothing happened during this copy: it is good
  EXPECT_EQ(copy, Rec(0));

  ASSERT_EQ(ring.Read(1, view), Status::kOk);
  std::copy(view.begin(), view.begin() + 2, copy.begin());  // half copied, then the sampler runs
  ASSERT_TRUE(ring.Push(Rec(9)));
  ASSERT_TRUE(ring.Push(Rec(10)));
  ASSERT_TRUE(ring.Push(Rec(0xABCD000Bu)));  // index 11 lands in record 1's slot
  std::copy(view.begin() + 2, view.end(), copy.begin() + 2);
  EXPECT_FALSE(ring.Intact(1));  // so the copy is refused: it is torn, half record 1, half 11
  EXPECT_EQ(copy, (std::array<std::uint8_t, 4>{0x01, 0x00, 0xCD, 0xAB}));
}

}  // namespace
}  // namespace vibid::fw
