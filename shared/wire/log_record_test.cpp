#include "vibid/shared/wire/log_record.hpp"

#include <gtest/gtest.h>

#include <array>

#include "golden_vectors.hpp"

namespace vibid::wire {
namespace {

// Record sizes from the layout documented in log_record.hpp: converter channels 2 bytes,
// encoders 4, d_hat 4; a stream data report's 58-byte payload spends 4 bytes on its first
// record's tick, leaving 54 for records.
TEST(LogLayout, SizesByHand) {
  EXPECT_EQ((LogLayout{kAllChannelsMask, kAcqFlagLogDob}.RecordBytes()), 20u);
  EXPECT_EQ((LogLayout{kAllChannelsMask, kAcqFlagLogDob}.RecordsPerReport()), 2u);
  EXPECT_EQ((LogLayout{kAllChannelsMask, 0}.RecordsPerReport()), 3u);
  EXPECT_EQ((LogLayout{0b100011, kAcqFlagLogDob}.RecordBytes()), 12u);
  EXPECT_EQ((LogLayout{0b100011, kAcqFlagLogDob}.StoredRecordBytes()), 16u);
  EXPECT_EQ((LogLayout{0b100011, kAcqFlagLogDob}.RecordsPerReport()), 4u);
  EXPECT_EQ((LogLayout{0b001101, 0}.RecordBytes()), 6u);  // force1, acc1, acc2: the modal test
  EXPECT_EQ((LogLayout{0b001101, 0}.RecordsPerReport()), 9u);
  EXPECT_EQ((LogLayout{0b000001, 0}.RecordBytes()), 2u);
  EXPECT_EQ((LogLayout{0b000001, 0}.RecordsPerReport()), 27u);
  EXPECT_FALSE((LogLayout{0, 0}.Valid()));
  EXPECT_FALSE((LogLayout{0x40, 0}.Valid()));
  EXPECT_FALSE((LogLayout{1, 0x08}.Valid()));  // an unknown flag
  // The residual test's word: 4 bytes more, only beside d_hat.
  EXPECT_EQ((LogLayout{kAllChannelsMask, kAcqFlagLogDob | kAcqFlagLogWatch}.RecordBytes()), 24u);
  EXPECT_EQ((LogLayout{kAllChannelsMask, kAcqFlagLogDob | kAcqFlagLogWatch}.RecordsPerReport()),
            2u);
  EXPECT_EQ((LogLayout{0b001001, kAcqFlagLogDob | kAcqFlagLogWatch}.RecordsPerReport()), 4u);
  EXPECT_FALSE((LogLayout{1, kAcqFlagLogWatch}.Valid()));
  EXPECT_TRUE((LogLayout{1, kAcqFlagLogDob | kAcqFlagLogWatch}.Valid()));
}

// The word after d_hat, little-endian like every field (bytes written out by hand).
TEST(LogRecord, CarriesTheResidualTestsWordAfterDhat) {
  const LogLayout layout{0b000001, kAcqFlagLogDob | kAcqFlagLogWatch};
  LogRecord rec;
  rec.raw[0] = 0x1230;
  rec.d_hat = -2;
  rec.watch = kLogWatchStaleBit | 0x12345u;  // stale, g = 0x12345 / 2^16 = 1.1378
  std::array<std::uint8_t, 10> bytes{};
  EncodeLogRecord(layout, rec, bytes);
  const std::array<std::uint8_t, 10> expected{0x30, 0x12, 0xFE, 0xFF, 0xFF,
                                              0xFF, 0x45, 0x23, 0x01, 0x80};
  EXPECT_EQ(bytes, expected);
  LogRecord back;
  ASSERT_EQ(DecodeLogRecord(layout, bytes, back), Status::kOk);
  EXPECT_EQ(back.raw[0], 0x1230);
  EXPECT_EQ(back.d_hat, -2);
  EXPECT_EQ(back.watch, 0x80012345u);
  ASSERT_EQ(DecodeLogRecord(LogLayout{0b000001, kAcqFlagLogDob},
                            std::span<const std::uint8_t>(bytes).first(6), back),
            Status::kOk);
  EXPECT_EQ(back.watch, 0u);
}

// Golden stream report 0 (scripts/golden/wire_vectors.py): first tick 1000, records 10..12 at
// decimation 5: force1 (2048 + i) << 4, force2 (2047 - i) << 4, encoder2 -3 i, d_hat -2^20 + i.
TEST(LogRecord, DecodesGoldenReport) {
  const Report r = testing::GoldenReport("log_stream_0");
  const LogLayout layout{0b100011, kAcqFlagLogDob};
  const auto payload = PayloadOf(r);
  ASSERT_EQ(payload.size(), 4u + 3u * 12u);
  std::array<LogRecord, kMaxRecordsPerReport> recs{};
  std::size_t n = 0;
  ASSERT_EQ(DecodeLogPayload(layout, 5, payload, recs, n), Status::kOk);
  ASSERT_EQ(n, 3u);
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = static_cast<std::int32_t>(i);
    EXPECT_EQ(recs[i].sample_index, 1000u + 5u * i);
    EXPECT_EQ(recs[i].raw[0], (2048 + k) * 16);
    EXPECT_EQ(recs[i].raw[1], (2047 - k) * 16);
    EXPECT_EQ(recs[i].raw[2], 0);  // not in the layout
    EXPECT_EQ(recs[i].raw[5], -3 * k);
    EXPECT_EQ(recs[i].d_hat, -(1 << 20) + k);

    std::array<std::uint8_t, kMaxLogRecordBytes> again{};
    EncodeLogRecord(layout, recs[i], again);
    for (std::size_t b = 0; b < 12; ++b) EXPECT_EQ(again[b], payload[4 + 12 * i + b]);
  }
  // The report after the gap starts at tick 1020 (the record of tick 1015 was dropped).
  ASSERT_EQ(DecodeLogPayload(layout, 5, PayloadOf(testing::GoldenReport("log_stream_1")), recs, n),
            Status::kOk);
  ASSERT_EQ(n, 2u);
  EXPECT_EQ(recs[0].sample_index, 1020u);
  EXPECT_EQ(recs[1].sample_index, 1025u);
  EXPECT_EQ(recs[1].raw[0], (2048 + 4) * 16);

  LogRecord rec;
  EXPECT_EQ(DecodeLogRecord(layout, payload.subspan(4, 11), rec), Status::kInvalidArgument);
  EXPECT_EQ(DecodeLogPayload(layout, 5, payload.first(4 + 11), recs, n), Status::kInvalidArgument);
  EXPECT_EQ(DecodeLogPayload(layout, 5, payload.first(4), recs, n), Status::kInvalidArgument);
  EXPECT_EQ(DecodeLogPayload(layout, 0, payload, recs, n), Status::kInvalidArgument);
  EXPECT_EQ(DecodeLogPayload(layout, 5, payload, std::span(recs).first(2), n),
            Status::kInvalidArgument);
}

// Converter values beyond 16 bits are clamped (a filter overshoot near full scale).
TEST(LogRecord, ClampsConverterValues) {
  const LogLayout layout{0b000011, 0};
  LogRecord rec;
  rec.raw[0] = 70000;
  rec.raw[1] = -5;
  std::array<std::uint8_t, kMaxLogRecordBytes> bytes{};
  EncodeLogRecord(layout, rec, bytes);
  LogRecord back;
  ASSERT_EQ(DecodeLogRecord(layout, std::span(bytes).first(4), back), Status::kOk);
  EXPECT_EQ(back.raw[0], kLogAdcMax);
  EXPECT_EQ(back.raw[1], 0);
}

}  // namespace
}  // namespace vibid::wire
