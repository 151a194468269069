// Calibration over the wire: multi-report upload (with corrupted, reordered and short reports
// refused), commit, read-back stream, persistence across a reboot, and the record in use.
#include <gtest/gtest.h>

#include <array>

#include "core_harness.hpp"
#include "test_records.hpp"
#include "vibid/shared/wire/crc32.hpp"

namespace vibid::fw {
namespace {

using testing::CoreHarness;
using testing::Encoded;
using testing::Response;
using testing::TestRecord;
using wire::Command;

wire::Report Begin(std::span<const std::uint8_t> record, std::uint16_t token) {
  wire::Report r{};
  EXPECT_EQ(wire::BuildCalPutBegin(record, token, r), Status::kOk);
  return r;
}

wire::Report Chunk(std::span<const std::uint8_t> record, std::size_t i, std::uint16_t token) {
  wire::Report r{};
  (void)wire::BuildCalPutData(record, i, token, r);
  return r;
}

TEST(CoreCalibration, UploadCommitReadBackAndReboot) {
  CoreHarness h;
  (void)h.core.Boot();
  const auto record = Encoded(TestRecord(7));
  ASSERT_EQ(h.Upload(record), Status::kOk);

  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  EXPECT_EQ(s.cal_staged, 1);
  EXPECT_EQ(s.cal_state, wire::CalState::kUncalibrated);  // staged is not committed

  const Response commit = h.Request(Command::kCalCommit);
  ASSERT_EQ(commit.status(), Status::kOk);
  wire::CalCommitResponse committed;
  ASSERT_EQ(wire::Decode(commit.payload(), committed), Status::kOk);
  EXPECT_EQ(committed.slot, 0);
  EXPECT_EQ(committed.sequence, 1u);

  wire::InfoResponse board_info;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetInfo).payload(), board_info), Status::kOk);
  EXPECT_EQ(board_info.cal_state, wire::CalState::kCalibrated);
  EXPECT_EQ(board_info.cal_slot, 0);
  EXPECT_EQ(board_info.cal_crc, wire::StoredRecordCrc(record));

  // cal-get streams the record back: 17 data reports + trailer, checked by the host decoder.
  h.link.ClearOut();
  wire::Report request{};
  ASSERT_EQ(wire::BuildReport(Command::kCalGet, 0x3333, 0, 0, Status::kOk, {}, request),
            Status::kOk);
  h.link.Push(request);
  h.Drain();
  wire::StreamDecoder decoder(Command::kCalGet, 0x3333);
  std::array<std::uint8_t, wire::kCalRecordBytes> back{};
  std::size_t n = 0;
  wire::Report in{};
  wire::StreamDecoder::Step step;
  while (h.link.Pop(in)) {
    step = decoder.Feed(in);
    if (step.event != wire::StreamDecoder::Event::kData) break;
    for (const std::uint8_t b : step.payload) back[n++] = b;
  }
  ASSERT_EQ(step.event, wire::StreamDecoder::Event::kEnd);
  EXPECT_EQ(decoder.data_reports(), 18u);  // 1020 bytes in stream data reports of 58
  EXPECT_EQ(n, wire::kCalRecordBytes);
  EXPECT_TRUE(back == record);
  wire::CalGetTrailer trailer;
  ASSERT_EQ(wire::Decode(step.payload, trailer), Status::kOk);
  EXPECT_EQ(trailer.slot, 0);
  EXPECT_EQ(trailer.sequence, 1u);

  // Reboot on the same flash: the record is still there.
  CoreHarness rebooted;
  rebooted.fake.flash = h.fake.flash;
  EXPECT_EQ(rebooted.core.Boot(), Status::kOk);
  ASSERT_EQ(wire::Decode(rebooted.Request(Command::kGetInfo).payload(), board_info), Status::kOk);
  EXPECT_EQ(board_info.cal_state, wire::CalState::kCalibrated);
  EXPECT_EQ(board_info.cal_crc, wire::StoredRecordCrc(record));
}

TEST(CoreCalibration, CorruptedReportIsRejectedAndNothingStaged) {
  CoreHarness h;
  const auto record = Encoded(TestRecord(1));
  ASSERT_EQ(h.Raw(Begin(record, 0x11)).status(), Status::kOk);
  Status last = Status::kOk;
  for (std::size_t i = 0; i < wire::CalPutChunkCount(record.size()); ++i) {
    wire::Report chunk = Chunk(record, i, 0x11);
    if (i == 5) chunk[wire::kOffPayload + 17] ^= 0x20;  // one bit flipped on the way
    const Response r = h.Raw(chunk);
    last = r.status();
    if (i + 1 < wire::CalPutChunkCount(record.size())) {
      EXPECT_EQ(last, Status::kOk);
    }
  }
  EXPECT_EQ(last, Status::kDataLoss);  // the verdict on the assembled record
  EXPECT_EQ(h.Request(Command::kCalCommit).status(), Status::kFailedPrecondition);
  // The host starts over and succeeds.
  ASSERT_EQ(h.Upload(record), Status::kOk);
  EXPECT_EQ(h.Request(Command::kCalCommit).status(), Status::kOk);
}

TEST(CoreCalibration, OutOfOrderOrShortChunksAbortTheTransfer) {
  CoreHarness h;
  const auto record = Encoded(TestRecord(1));
  const wire::Report begin = Begin(record, 0x12);

  ASSERT_EQ(h.Raw(begin).status(), Status::kOk);
  EXPECT_EQ(h.Raw(Chunk(record, 0, 0x12)).status(), Status::kOk);
  EXPECT_EQ(h.Raw(Chunk(record, 2, 0x12)).status(), Status::kOutOfRange);  // chunk 1 skipped
  EXPECT_EQ(h.Raw(Chunk(record, 1, 0x12)).status(), Status::kFailedPrecondition);  // aborted

  ASSERT_EQ(h.Raw(begin).status(), Status::kOk);
  wire::Report shorter = Chunk(record, 0, 0x12);
  shorter[wire::kOffPayloadLength] = 51;
  EXPECT_EQ(h.Raw(shorter).status(), Status::kInvalidArgument);

  ASSERT_EQ(h.Raw(begin).status(), Status::kOk);
  EXPECT_EQ(h.Raw(Chunk(record, 0, 0x12)).status(), Status::kOk);
  EXPECT_EQ(h.Raw(Chunk(record, 0, 0x12)).status(), Status::kOutOfRange);  // repeated chunk
}

TEST(CoreCalibration, WrongAnnouncedCrcIsDataLoss) {
  CoreHarness h;
  const auto record = Encoded(TestRecord(1));
  const wire::CalPutBeginRequest begin{.record_bytes = wire::kCalRecordBytes,
                                       .crc32 = wire::ComputeCrc32(record) ^ 1u};
  ASSERT_EQ(h.Request(Command::kCalPutBegin, begin).status(), Status::kOk);
  Status last = Status::kOk;
  for (std::size_t i = 0; i < wire::CalPutChunkCount(record.size()); ++i) {
    last = h.Raw(Chunk(record, i, h.last_token)).status();
  }
  EXPECT_EQ(last, Status::kDataLoss);
}

TEST(CoreCalibration, InvalidRecordIsRefusedOnTheLastChunk) {
  CoreHarness h;
  wire::CalibrationRecord bad = TestRecord(1);
  bad.mass_kg[0] = -1.0f;  // not positive definite; CRCs are all consistent
  EXPECT_EQ(h.Upload(Encoded(bad)), Status::kInvalidArgument);
  EXPECT_EQ(h.Request(Command::kCalCommit).status(), Status::kFailedPrecondition);
}

TEST(CoreCalibration, NoCommitWhileAcquiring) {
  CoreHarness h;
  ASSERT_EQ(h.Upload(Encoded(TestRecord(1))), Status::kOk);
  wire::AcqConfigureRequest c;
  c.sample_period_us = 1000;
  c.channel_mask = 1;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
  EXPECT_EQ(h.Request(Command::kCalCommit).status(), Status::kFailedPrecondition);
  EXPECT_EQ(h.fake.flash.steps(), 0u);  // flash untouched
  ASSERT_EQ(h.Request(Command::kAcqStop).status(), Status::kOk);
  EXPECT_EQ(h.Request(Command::kCalCommit).status(), Status::kOk);  // still staged
}

TEST(CoreCalibration, CommittedScalingIsApplied) {
  CoreHarness h;
  ASSERT_EQ(h.Upload(Encoded(TestRecord(1))), Status::kOk);
  ASSERT_EQ(h.Request(Command::kCalCommit).status(), Status::kOk);
  wire::AcqConfigureRequest c;
  c.sample_period_us = 1000;
  c.channel_mask = wire::kAllChannelsMask;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
  h.EmitRamp(1, {2048 + 1024, 2048 - 512, 2048, 2049, 1000, -1000}, 0);
  wire::LatestResponse latest;
  ASSERT_EQ(wire::Decode(h.Request(Command::kReadLatest).payload(), latest), Status::kOk);
  // TestRecord: load cells and accelerometers (raw - 2048) * 2^20, encoders raw * 2^16.
  EXPECT_EQ(latest.calibrated[0], 1 << 30);  // half of full scale: 50 N of 100 N
  EXPECT_EQ(latest.calibrated[1], -(1 << 29));
  EXPECT_EQ(latest.calibrated[2], 0);
  EXPECT_EQ(latest.calibrated[3], 1 << 20);
  EXPECT_EQ(latest.calibrated[4], 1000 << 16);
  EXPECT_EQ(latest.calibrated[5], -1000 * 65536);
}

}  // namespace
}  // namespace vibid::fw
