#include "vibid/shared/wire/log_record.hpp"

#include <gtest/gtest.h>

#include <array>

#include "golden_vectors.hpp"

namespace vibid::wire {
namespace {

TEST(LogLayout, SizesByHand) {
  EXPECT_EQ((LogLayout{kAllChannelsMask, kAcqFlagLogDob}.RecordBytes()), 32u);
  EXPECT_EQ((LogLayout{0b100011, kAcqFlagLogDob}.RecordBytes()), 20u);
  EXPECT_EQ((LogLayout{0b100011, kAcqFlagLogDob}.RecordsPerReport()), 2u);
  EXPECT_EQ((LogLayout{0b000001, 0}.RecordBytes()), 8u);
  EXPECT_EQ((LogLayout{0b000001, 0}.RecordsPerReport()), 6u);
  EXPECT_FALSE((LogLayout{0, 0}.Valid()));
  EXPECT_FALSE((LogLayout{0x40, 0}.Valid()));
  EXPECT_FALSE((LogLayout{1, 0x02}.Valid()));
}

// Golden stream report 0 holds records 10 and 11 (scripts/golden/wire_vectors.py):
// sample_index 1000 + 5 i, force1 2048 + i, force2 2047 - i, encoder2 -3 i, d_hat -2^20 + i.
TEST(LogRecord, DecodesGoldenRecords) {
  const Report r = testing::GoldenReport("log_stream_0");
  const LogLayout layout{0b100011, kAcqFlagLogDob};
  const auto payload = PayloadOf(r);
  ASSERT_EQ(payload.size(), 40u);
  for (std::size_t i = 0; i < 2; ++i) {
    LogRecord rec;
    ASSERT_EQ(DecodeLogRecord(layout, payload.subspan(20 * i, 20), rec), Status::kOk);
    const auto k = static_cast<std::int32_t>(i);
    EXPECT_EQ(rec.sample_index, 1000u + 5u * i);
    EXPECT_EQ(rec.raw[0], 2048 + k);
    EXPECT_EQ(rec.raw[1], 2047 - k);
    EXPECT_EQ(rec.raw[2], 0);  // not in the layout
    EXPECT_EQ(rec.raw[5], -3 * k);
    EXPECT_EQ(rec.d_hat, -(1 << 20) + k);

    std::array<std::uint8_t, kMaxLogRecordBytes> again{};
    EncodeLogRecord(layout, rec, again);
    for (std::size_t b = 0; b < 20; ++b) EXPECT_EQ(again[b], payload[20 * i + b]);
  }
  LogRecord rec;
  EXPECT_EQ(DecodeLogRecord(layout, payload.first(19), rec), Status::kInvalidArgument);
}

}  // namespace
}  // namespace vibid::wire
