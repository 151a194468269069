#include "vibid/shared/wire/stream.hpp"

#include <gtest/gtest.h>

#include <array>

#include "golden_vectors.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::wire {
namespace {

using Event = StreamDecoder::Event;

// Two data reports and the trailer (scripts/golden/wire_vectors.py).
std::array<Report, 3> GoldenLogStream() {
  return {testing::GoldenReport("log_stream_0"), testing::GoldenReport("log_stream_1"),
          testing::GoldenReport("log_stream_2")};
}

TEST(StreamDecoder, AcceptsGoldenLogStream) {
  StreamDecoder d(Command::kLogRead, 0x7777);
  const auto reports = GoldenLogStream();
  for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(d.Feed(reports[i]).event, Event::kData);
  const auto end = d.Feed(reports[2]);
  ASSERT_EQ(end.event, Event::kEnd);
  LogTrailer t;
  ASSERT_EQ(Decode(end.payload, t), Status::kOk);
  EXPECT_EQ(t.stream.total_bytes, 68u);  // two ticks of 4 bytes, 5 records of 12 bytes
  EXPECT_EQ(t.first_record, 10u);
  EXPECT_EQ(t.record_count, 5u);
  EXPECT_EQ(t.record_bytes, 12);
  EXPECT_EQ(t.acq_state, AcqState::kDone);
  EXPECT_EQ(t.dropped_records, 1u);
  EXPECT_EQ(t.records_written, 15u);
  EXPECT_EQ(d.total_bytes(), 68u);
  EXPECT_TRUE(d.finished());
  EXPECT_EQ(d.Feed(reports[0]).status, Status::kFailedPrecondition);
}

TEST(StreamEncoder, ReproducesGoldenLogStream) {
  const auto golden = GoldenLogStream();
  StreamEncoder e;
  e.Begin(Command::kLogRead, 0x7777);
  for (std::size_t i = 0; i < 2; ++i) {
    Report out{};
    ASSERT_EQ(e.Data(PayloadOf(golden[i]), out), Status::kOk);
    EXPECT_TRUE(out == golden[i]) << "report " << i;
  }
  LogTrailer t;
  t.first_record = 10;
  t.record_count = 5;
  t.record_bytes = 12;
  t.channel_mask = 0b100011;
  t.acq_flags = kAcqFlagLogDob | kAcqFlagStream;
  t.sample_period_us = 200;
  t.decimation = 5;
  t.acq_state = AcqState::kDone;
  t.trigger_record = 0;
  t.dropped_records = 1;
  t.overrun_count = 0;
  t.records_written = 15;
  std::array<std::uint8_t, LogTrailer::kBytes> trailer{};
  Encode(t, trailer);
  Report out{};
  ASSERT_EQ(e.End(trailer, out), Status::kOk);
  EXPECT_TRUE(out == golden[2]);
}

TEST(StreamDecoder, DetectsSequenceGap) {
  StreamDecoder d(Command::kLogRead, 0x7777);
  const auto reports = GoldenLogStream();
  EXPECT_EQ(d.Feed(reports[0]).event, Event::kData);
  const auto step = d.Feed(reports[2]);  // report 1 lost: the trailer's sequence is 2
  EXPECT_EQ(step.event, Event::kError);
  EXPECT_EQ(step.status, Status::kDataLoss);
}

TEST(StreamDecoder, DetectsMissingLastDataReport) {
  StreamDecoder d(Command::kLogRead, 0x7777);
  const auto reports = GoldenLogStream();
  d.Feed(reports[0]);
  EXPECT_EQ(d.Feed(reports[2]).status, Status::kDataLoss);  // trailer says 2 data reports
}

TEST(StreamDecoder, DetectsCorruptedPayloadByCrc) {
  StreamDecoder d(Command::kLogRead, 0x7777);
  auto reports = GoldenLogStream();
  reports[1][kOffPayload + 5] ^= 0x01;
  for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(d.Feed(reports[i]).event, Event::kData);
  const auto step = d.Feed(reports[2]);
  EXPECT_EQ(step.event, Event::kError);
  EXPECT_EQ(step.status, Status::kDataLoss);
}

TEST(StreamDecoder, IgnoresStaleAndReportsRefusal) {
  StreamDecoder d(Command::kLogRead, 0x7778);
  const auto reports = GoldenLogStream();
  EXPECT_EQ(d.Feed(reports[0]).event, Event::kStale);  // token of an earlier request
  Report refusal{};
  ASSERT_EQ(
      BuildReport(Command::kLogRead, 0x7778, 0, kFlagResponse, Status::kOutOfRange, {}, refusal),
      Status::kOk);
  const auto step = d.Feed(refusal);
  EXPECT_EQ(step.event, Event::kRefused);
  EXPECT_EQ(step.status, Status::kOutOfRange);
}

TEST(StreamDecoder, RejectsBrokenHeader) {
  StreamDecoder d(Command::kLogRead, 0x7777);
  auto reports = GoldenLogStream();
  reports[0][0] = 0;  // neither a stream data tag nor a magic
  EXPECT_EQ(d.Feed(reports[0]).status, Status::kDataLoss);
}

// Hand-decoded stream data report 0 (scripts/golden/wire_vectors.py): d5 | 28 | 77 77 | 00 00 |
// payload (40 bytes: the tick 1000 and three 12-byte records) | zeros.
TEST(StreamData, GoldenReportByHand) {
  const Report r = testing::GoldenReport("log_stream_0");
  EXPECT_TRUE(IsStreamData(r));
  StreamDataHeader h;
  ASSERT_EQ(DecodeStreamData(r, h), Status::kOk);
  EXPECT_EQ(h.token, 0x7777);
  EXPECT_EQ(h.sequence, 0);
  EXPECT_EQ(h.payload_length, 40);
  EXPECT_EQ(PayloadOf(r).size(), 40u);
  EXPECT_EQ(PayloadOf(r)[0], 0xE8);  // 1000 = 0x03E8
  Report again{};
  ASSERT_EQ(EncodeStreamData(0x7777, 0, PayloadOf(r), again), Status::kOk);
  EXPECT_TRUE(again == r);
  Header full;
  EXPECT_EQ(DecodeHeader(r, full), Status::kDataLoss);  // not a full report
  std::array<std::uint8_t, kMaxStreamPayload + 1> big{};
  EXPECT_EQ(EncodeStreamData(1, 0, big, again), Status::kOutOfRange);
  EXPECT_EQ(EncodeStreamData(1, 0, {}, again), Status::kOutOfRange);
  Report bad = r;
  bad[1] = 59;  // longer than a stream data report holds
  EXPECT_EQ(DecodeStreamData(bad, h), Status::kInvalidArgument);
}

// A stream that follows a long acquisition wraps its 16-bit sequence: report 65536 is
// numbered 0 again, and the decoder, counting modulo 2^16 too, still sees no gap.
TEST(Stream, SequenceWrapsAfter65535Reports) {
  StreamEncoder e;
  StreamDecoder d(Command::kLogRead, 0x0101);
  e.Begin(Command::kLogRead, 0x0101);
  const std::array<std::uint8_t, 8> payload{1, 2, 3, 4, 5, 6, 7, 8};
  Report out{};
  for (std::uint32_t i = 0; i < 65537; ++i) {
    ASSERT_EQ(e.Data(payload, out), Status::kOk);
    ASSERT_EQ(d.Feed(out).event, Event::kData) << "report " << i;
  }
  StreamDataHeader h;
  ASSERT_EQ(DecodeStreamData(out, h), Status::kOk);
  EXPECT_EQ(h.sequence, 0u);  // report 65536
  std::array<std::uint8_t, StreamTrailer::kBytes> trailer{};
  ASSERT_EQ(e.End(trailer, out), Status::kOk);
  const auto end = d.Feed(out);
  ASSERT_EQ(end.event, Event::kEnd);
  EXPECT_EQ(d.total_bytes(), 65537u * 8u);
}

// cal-put reports cut from the golden record equal the script's.
TEST(CalPut, BuildsGoldenReports) {
  std::array<std::uint8_t, kCalRecordBytes> record{};
  ASSERT_EQ(testing::GoldenVector("calibration_record", record), kCalRecordBytes);
  EXPECT_EQ(CalPutChunkCount(record.size()), 20u);  // ceil(1020 / 52)
  Report out{};
  ASSERT_EQ(BuildCalPutBegin(record, 0x0C0C, out), Status::kOk);
  EXPECT_TRUE(out == testing::GoldenReport("cal_put_begin"));
  ASSERT_EQ(BuildCalPutData(record, 0, 0x0C0C, out), Status::kOk);
  EXPECT_TRUE(out == testing::GoldenReport("cal_put_data_0"));
  ASSERT_EQ(BuildCalPutData(record, 19, 0x0C0C, out), Status::kOk);
  EXPECT_TRUE(out == testing::GoldenReport("cal_put_data_19"));
  EXPECT_EQ(PayloadOf(out).size(), kCalRecordBytes - 19u * 52u);
  EXPECT_EQ(BuildCalPutData(record, 20, 0x0C0C, out), Status::kOutOfRange);
}

}  // namespace
}  // namespace vibid::wire
