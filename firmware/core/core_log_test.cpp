// Acquisition and log streaming: decimation, triggers with pre-trigger records, record limits,
// overruns and drops counted, a lost report detected by the host decoder and the pull resumed
// with nothing lost or duplicated.
#include <gtest/gtest.h>

#include <array>

#include "core_harness.hpp"
#include "vibid/shared/fixed/decimator.hpp"

namespace vibid::fw {
namespace {

using testing::CoreHarness;
using testing::PulledLog;
using testing::PullLog;
using wire::Command;

// Frame k reads channel c = 100 * c + k (uncalibrated board: calibrated = raw).
constexpr std::array<std::int32_t, wire::kChannelCount> kBase{0, 100, 200, 300, 400, 500};

/// What the log holds for a raw value of channel c: converter codes in 12.4, encoder counts.
std::int32_t Logged(std::size_t c, std::int32_t raw) { return c < 4 ? raw * 16 : raw; }

wire::AcqConfigureRequest Config(std::uint8_t mask, std::uint16_t decimation) {
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;
  c.channel_mask = mask;
  c.decimation = decimation;
  return c;
}

/// Config(mask, 1) armed until force `channel` crosses `threshold`, keeping `pretrigger` records
/// from before the crossing.
wire::AcqConfigureRequest Triggered(std::uint8_t mask, wire::TriggerMode mode, std::uint8_t channel,
                                    std::int32_t threshold, std::uint32_t pretrigger) {
  wire::AcqConfigureRequest c = Config(mask, 1);
  c.trigger_mode = mode;
  c.trigger_channel = channel;
  c.trigger_threshold = threshold;
  c.pretrigger_records = pretrigger;
  return c;
}

TEST(CoreLog, ImmediateAcquisitionStreamsEveryRecord) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(wire::kAllChannelsMask, 1)), Status::kOk);
  h.EmitRamp(10, kBase, 1);
  const PulledLog log = PullLog(h, 0, 0);
  ASSERT_EQ(log.last_event, wire::StreamDecoder::Event::kEnd);
  ASSERT_EQ(log.status, Status::kOk);
  ASSERT_EQ(log.count, 10u);
  for (std::uint32_t k = 0; k < 10; ++k) {
    EXPECT_EQ(log.records[k].sample_index, k);
    for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
      EXPECT_EQ(log.records[k].raw[c], Logged(c, kBase[c] + static_cast<std::int32_t>(k)));
    }
  }
  EXPECT_EQ(log.trailer.first_record, 0u);
  EXPECT_EQ(log.trailer.record_count, 10u);
  EXPECT_EQ(log.trailer.record_bytes, 16);
  EXPECT_EQ(log.trailer.sample_period_us, 200u);
  EXPECT_EQ(log.trailer.decimation, 1);
  EXPECT_EQ(log.trailer.trigger_record, 0u);
  EXPECT_EQ(log.trailer.records_written, 10u);
  EXPECT_EQ(log.trailer.acq_state, wire::AcqState::kAcquiring);
  EXPECT_EQ(log.trailer.dropped_records, 0u);
}

// A linear-phase low-pass with unit DC gain maps a ramp onto the same ramp delayed by its group
// delay, exactly in integers (sum of h = 1, sum of k h = delay). The log starts once the filter
// has settled (tick >= twice the delay, rounded up to an output tick), so every decimated record
// equals the input at tick - delay.
TEST(CoreLog, DecimationFiltersEveryChannelAlike) {
  CoreHarness h;
  // Force 2 and encoder 1 only (mask 0b010010), decimated by 5: 6-byte records, 9 per report.
  ASSERT_EQ(h.StartAcquisition(Config(0b010010, 5)), Status::kOk);
  constexpr std::uint32_t kFrames = 600;
  h.EmitRamp(kFrames, kBase, 1);
  const PulledLog log = PullLog(h, 0, 0);
  ASSERT_EQ(log.status, Status::kOk);
  const std::uint32_t delay = fixed::DecimatorDelayTicks(5);
  ASSERT_EQ(delay, 47u);            // the /5 design's 95 taps (scripts/golden/decimator_design.py)
  const std::uint32_t settle = 95;  // 2 x 47 rounded up to a multiple of 5
  ASSERT_EQ(log.count, (kFrames - settle) / 5);  // ticks 95, 100, ..., 595
  for (std::uint32_t i = 0; i < log.count; ++i) {
    const std::uint32_t tick = log.records[i].sample_index;
    EXPECT_EQ(tick, settle + 5 * i);
    const auto input_tick = static_cast<std::int32_t>(tick - delay);
    EXPECT_EQ(log.records[i].raw[0], 0);  // not logged
    EXPECT_EQ(log.records[i].raw[1], Logged(1, 100 + input_tick)) << "tick " << tick;
    EXPECT_EQ(log.records[i].raw[4], Logged(4, 400 + input_tick)) << "tick " << tick;
  }
  EXPECT_EQ(log.trailer.record_bytes, 6);
  EXPECT_EQ(log.trailer.decimation, 5);
  EXPECT_EQ(log.trailer.channel_mask, 0b010010);
}

TEST(CoreLog, LostReportIsDetectedAndThePullResumes) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(wire::kAllChannelsMask, 1)), Status::kOk);
  h.EmitRamp(40, kBase, 1);
  // 16-byte records: three per report. Report 2 (records 6..8) is lost on the way.
  const PulledLog broken = PullLog(h, 0, 0, 2);
  EXPECT_EQ(broken.last_event, wire::StreamDecoder::Event::kError);
  EXPECT_EQ(broken.status, Status::kDataLoss);

  // The host kept records 0..5 intact and asks again from 6.
  const PulledLog resumed = PullLog(h, 6, 0);
  ASSERT_EQ(resumed.status, Status::kOk);
  ASSERT_EQ(resumed.count, 34u);
  for (std::uint32_t i = 0; i < resumed.count; ++i) {
    EXPECT_EQ(resumed.records[i].sample_index, 6 + i);  // nothing lost, nothing repeated
  }
  EXPECT_EQ(resumed.trailer.first_record, 6u);
}

TEST(CoreLog, NewRequestAbandonsTheRunningStream) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(wire::kAllChannelsMask, 1)), Status::kOk);
  h.EmitRamp(40, kBase, 1);
  h.link.in_busy = true;  // the host stops reading mid-stream
  wire::Report request{};
  std::array<std::uint8_t, wire::LogReadRequest::kBytes> p{};
  wire::Encode(wire::LogReadRequest{}, p);
  ASSERT_EQ(wire::BuildReport(Command::kLogRead, 1, 0, 0, Status::kOk, p, request), Status::kOk);
  h.link.Push(request);
  h.core.Poll();
  h.link.in_busy = false;
  // A ping arrives: the stream is dropped after the report already offered.
  EXPECT_EQ(h.Request(Command::kPing).status(), Status::kOk);
  wire::Report in{};
  std::size_t extra = 0;
  while (h.link.Pop(in)) ++extra;
  h.Drain();
  EXPECT_EQ(h.link.pending_out(), 0u);
  EXPECT_LE(extra, 1u);
}

TEST(CoreLog, MaxRecordsLimitsTheStream) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(0b000001, 1)), Status::kOk);  // 2-byte records, 27/report
  h.EmitRamp(20, kBase, 1);
  const PulledLog log = PullLog(h, 2, 13);
  ASSERT_EQ(log.status, Status::kOk);
  ASSERT_EQ(log.count, 13u);
  EXPECT_EQ(log.records[0].sample_index, 2u);
  EXPECT_EQ(log.records[12].sample_index, 14u);
  EXPECT_EQ(log.trailer.records_written, 20u);
}

TEST(CoreLog, ForceTriggerKeepsPreTriggerRecords) {
  CoreHarness h;
  wire::AcqConfigureRequest c = Triggered(0b000001, wire::TriggerMode::kRising, 0, 30, 5);
  c.record_limit = 8;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
  // Force 1 reads k at frame k: it reaches 30 at frame 30.
  h.EmitRamp(29, kBase, 1);
  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  EXPECT_EQ(s.acq_state, wire::AcqState::kArmed);
  EXPECT_EQ(s.trigger_record, wire::kNoRecord);
  EXPECT_EQ(s.records_written, 0u);
  EXPECT_EQ(h.Request(Command::kLogRead, wire::LogReadRequest{.first_record = 1}).status(),
            Status::kOutOfRange);  // nothing in the log before the trigger

  h.EmitRamp(20, kBase, 1);  // frames 29..48; trigger at 30, 8 records from there, then done
  h.core.Poll();
  EXPECT_FALSE(h.fake.frames.running());  // the core stopped the port at the record limit
  const PulledLog log = PullLog(h, 0, 0);
  ASSERT_EQ(log.status, Status::kOk);
  ASSERT_EQ(log.count, 13u);  // 5 before + 8 from the trigger
  for (std::uint32_t i = 0; i < 13; ++i) EXPECT_EQ(log.records[i].sample_index, 25 + i);
  EXPECT_EQ(log.records[5].raw[0], Logged(0, 30));  // the trigger record crossed the threshold
  EXPECT_EQ(log.trailer.trigger_record, 5u);
  EXPECT_EQ(log.trailer.acq_state, wire::AcqState::kDone);
}

TEST(CoreLog, FallingTriggerWithFewerFramesThanPreTrigger) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Triggered(0b000010, wire::TriggerMode::kFalling, 1, 98, 10)),
            Status::kOk);
  h.EmitRamp(6, kBase, -1);  // force 2 = 100 - k: reaches 98 at frame 2
  const PulledLog log = PullLog(h, 0, 0);
  ASSERT_EQ(log.status, Status::kOk);
  ASSERT_EQ(log.count, 6u);
  EXPECT_EQ(log.trailer.trigger_record, 2u);  // only 2 frames came before the trigger
  EXPECT_EQ(log.records[2].raw[1], Logged(1, 98));
}

TEST(CoreLog, FullLogDropsAndCountsNeverOverwrites) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(wire::kAllChannelsMask, 1)), Status::kOk);
  // 2048 / 20 (16-byte record and its 4-byte tick) = 102 records fit. 130 frames: 28 dropped.
  h.EmitRamp(130, kBase, 1);
  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  EXPECT_EQ(s.records_written, 102u);
  EXPECT_EQ(s.dropped_records, 28u);
  wire::InfoResponse board_info;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetInfo).payload(), board_info), Status::kOk);
  EXPECT_EQ(board_info.dropped_records, 28u);

  // Pulling from 50 releases 0..49; new frames fit again and carry on where they are.
  PulledLog log = PullLog(h, 50, 0);
  ASSERT_EQ(log.status, Status::kOk);
  EXPECT_EQ(log.trailer.dropped_records, 28u);
  ASSERT_EQ(log.count, 52u);
  EXPECT_EQ(log.records[51].sample_index, 101u);  // the first 102 frames were kept
  h.EmitRamp(5, kBase, 1);
  log = PullLog(h, 102, 0);
  ASSERT_EQ(log.status, Status::kOk);
  ASSERT_EQ(log.count, 5u);
  EXPECT_EQ(log.records[0].sample_index, 130u);  // a gap: the report starts at the new tick
}

wire::StatusResponse BoardStatus(CoreHarness& h) {
  wire::StatusResponse s;
  EXPECT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  return s;
}

// The way `vibid acquire` then `vibid log pull` use the board: pulls while sampling release
// what they received, yet after the stop the whole log (it fits) comes back from record 0,
// record for record what the first pulls got.
TEST(CoreLog, PulledRecordsCanBePulledAgainAfterTheStop) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(wire::kAllChannelsMask, 1)), Status::kOk);
  std::array<wire::LogRecord, 60> first_pass{};
  std::uint32_t next = 0;
  for (int round = 0; round < 3; ++round) {
    h.EmitRamp(20, kBase, 1);
    const PulledLog part = PullLog(h, next, 0);
    ASSERT_EQ(part.status, Status::kOk);
    ASSERT_EQ(part.count, 20u);
    for (std::size_t i = 0; i < part.count; ++i) first_pass[next + i] = part.records[i];
    next += 20;
  }
  EXPECT_EQ(BoardStatus(h).oldest_record, 0u);
  ASSERT_EQ(h.Request(Command::kAcqStop).status(), Status::kOk);

  const PulledLog again = PullLog(h, 0, 0);
  ASSERT_EQ(again.status, Status::kOk);
  ASSERT_EQ(again.count, 60u);
  for (std::size_t i = 0; i < 60; ++i) {
    EXPECT_EQ(again.records[i].sample_index, i);
    EXPECT_EQ(again.records[i].sample_index, first_pass[i].sample_index);
    EXPECT_EQ(again.records[i].raw, first_pass[i].raw);
  }
  EXPECT_EQ(again.trailer.acq_state, wire::AcqState::kIdle);
  // The last pull while sampling asked from 40; a second look at older records takes no space
  // back from the sampler.
  EXPECT_EQ(h.core.log().released(), 40u);
}

// Once the sampler reused a released record's slot, asking for that record is refused; the
// oldest record get-status names is the first one a pull gets.
TEST(CoreLog, OverwrittenRecordsAreRefused) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(wire::kAllChannelsMask, 1)), Status::kOk);
  h.EmitRamp(60, kBase, 1);
  ASSERT_EQ(PullLog(h, 60, 0).status, Status::kOk);  // releases 0..59
  // 102 slots of 20 bytes; 129 written: index 129 may take record 27's slot next.
  h.EmitRamp(69, kBase, 1);
  const wire::StatusResponse s = BoardStatus(h);
  EXPECT_EQ(s.records_written, 129u);
  EXPECT_EQ(s.oldest_record, 28u);
  EXPECT_EQ(s.dropped_records, 0u);
  EXPECT_EQ(PullLog(h, 27, 0).status, Status::kOutOfRange);
  EXPECT_EQ(PullLog(h, 0, 0).status, Status::kOutOfRange);
  const PulledLog log = PullLog(h, 28, 0);
  ASSERT_EQ(log.status, Status::kOk);
  ASSERT_EQ(log.count, 101u);
  for (std::uint32_t i = 0; i < log.count; ++i) EXPECT_EQ(log.records[i].sample_index, 28 + i);
}

// The sampler overwrites records a running stream has not sent yet: the stream ends with an
// out-of-range refusal under the request's own token, never with the newer records.
TEST(CoreLog, StreamOverrunBySamplerEndsOutOfRange) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(wire::kAllChannelsMask, 1)), Status::kOk);
  h.EmitRamp(60, kBase, 1);
  ASSERT_EQ(PullLog(h, 60, 0).status, Status::kOk);
  wire::Report request{};
  std::array<std::uint8_t, wire::LogReadRequest::kBytes> p{};
  wire::Encode(wire::LogReadRequest{.first_record = 0}, p);
  ASSERT_EQ(wire::BuildReport(Command::kLogRead, 77, 0, 0, Status::kOk, p, request), Status::kOk);
  h.link.ClearOut();
  h.link.Push(request);
  h.core.Poll();  // the first records go out, three per report
  const std::uint32_t sent = static_cast<std::uint32_t>(h.link.pending_out());
  ASSERT_GT(sent, 0u);
  ASSERT_LT(3 * sent, 60u);
  // written = 3 sent + 102: the slot of record 3 sent, the next one due, may be reused.
  h.EmitRamp(3 * sent + 102 - 60, kBase, 1);
  h.Drain();
  wire::StreamDecoder decoder(Command::kLogRead, 77);
  wire::Report in{};
  wire::StreamDecoder::Step last;
  while (h.link.Pop(in)) last = decoder.Feed(in);
  EXPECT_EQ(decoder.data_reports(), sent);
  EXPECT_EQ(last.event, wire::StreamDecoder::Event::kRefused);
  EXPECT_EQ(last.status, Status::kOutOfRange);
}

TEST(CoreLog, LostTicksAreCountedAsOverruns) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(0b000001, 1)), Status::kOk);
  h.EmitRamp(3, kBase, 1);
  h.fake.frames.Skip(4);
  h.EmitRamp(3, kBase, 1);
  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  EXPECT_EQ(s.overrun_count, 4u);
  EXPECT_EQ(s.ticks, 6u);
  const PulledLog log = PullLog(h, 0, 0);
  ASSERT_EQ(log.count, 6u);
  EXPECT_EQ(log.records[3].sample_index, 7u);  // the gap is visible in the sample index too
}

// acq-start with kAcqFlagStream: the log follows the acquisition as a log-read stream under
// acq-start's token, sending what is there and waiting (sending nothing) while the sampler is
// ahead of nothing, releasing what it sent, and ending with the trailer once the record limit
// stopped sampling and every record went out.
TEST(CoreLog, StreamedAcquisitionFollowsTheLogToItsEnd) {
  CoreHarness h;
  wire::AcqConfigureRequest c = Config(0b000101, 1);  // force 1, acc 1: 4-byte records, 13/report
  c.flags = wire::kAcqFlagStream;
  c.record_limit = 100;
  ASSERT_EQ(h.Request(Command::kAcqConfigure, c).status(), Status::kOk);
  ASSERT_EQ(h.Request(Command::kAcqStart).status(), Status::kOk);
  const std::uint16_t token = h.last_token;
  wire::StreamDecoder decoder(Command::kLogRead, token);
  std::uint32_t records = 0;
  std::uint32_t next_tick = 0;
  wire::Report in{};
  auto take = [&] {
    h.Drain();
    while (h.link.Pop(in)) {
      const auto step = decoder.Feed(in);
      if (step.event == wire::StreamDecoder::Event::kData) {
        std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
        std::size_t n = 0;
        ASSERT_EQ(wire::DecodeLogPayload(wire::LogLayout{0b000101, 0}, 1, step.payload, batch, n),
                  Status::kOk);
        for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(batch[k].sample_index, next_tick++);
        records += static_cast<std::uint32_t>(n);
      } else {
        ASSERT_EQ(step.event, wire::StreamDecoder::Event::kEnd);
      }
    }
  };
  take();
  EXPECT_EQ(records, 0u);  // nothing sampled yet: the stream waits
  EXPECT_FALSE(decoder.finished());
  h.EmitRamp(30, kBase, 1);
  take();
  EXPECT_EQ(records, 30u);  // what was there went out (reports of 13, 13 and 4)
  EXPECT_EQ(h.core.log().released(), 30u);
  EXPECT_FALSE(decoder.finished());
  h.EmitRamp(80, kBase, 1);  // the limit stops sampling after 100 records
  take();
  ASSERT_TRUE(decoder.finished());
  EXPECT_EQ(records, 100u);
  wire::LogTrailer t;
  ASSERT_EQ(wire::Decode(wire::PayloadOf(in), t), Status::kOk);
  EXPECT_EQ(t.first_record, 0u);
  EXPECT_EQ(t.record_count, 100u);
  EXPECT_EQ(t.acq_state, wire::AcqState::kDone);
  EXPECT_EQ(t.dropped_records, 0u);
}

// log-read with max_records kLogReadFollow while sampling: the stream acq-start would have sent,
// from the record asked for on (what a host sends when that stream broke off). It releases what
// it sent and ends once the record limit stopped sampling and every record went out.
TEST(CoreLog, FollowingLogReadResumesTheAcquisitionStream) {
  CoreHarness h;
  wire::AcqConfigureRequest c = Config(0b000101, 1);  // force 1, acc 1: 4-byte records, 13/report
  c.record_limit = 100;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
  h.EmitRamp(30, kBase, 1);
  wire::Report request{};
  std::array<std::uint8_t, wire::LogReadRequest::kBytes> p{};
  wire::Encode(wire::LogReadRequest{.first_record = 12, .max_records = wire::kLogReadFollow}, p);
  ASSERT_EQ(wire::BuildReport(Command::kLogRead, 9, 0, 0, Status::kOk, p, request), Status::kOk);
  h.link.Push(request);
  wire::StreamDecoder decoder(Command::kLogRead, 9);
  std::uint32_t next_tick = 12;
  wire::Report in{};
  auto take = [&] {
    h.Drain();
    while (h.link.Pop(in)) {
      const auto step = decoder.Feed(in);
      if (step.event == wire::StreamDecoder::Event::kData) {
        std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
        std::size_t n = 0;
        ASSERT_EQ(wire::DecodeLogPayload(wire::LogLayout{0b000101, 0}, 1, step.payload, batch, n),
                  Status::kOk);
        for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(batch[k].sample_index, next_tick++);
      } else {
        ASSERT_EQ(step.event, wire::StreamDecoder::Event::kEnd);
      }
    }
  };
  take();
  EXPECT_EQ(next_tick, 30u);  // records 12..29 went out
  EXPECT_FALSE(decoder.finished()) << "the stream waits for the sampler";
  EXPECT_EQ(h.core.log().released(), 30u);
  h.EmitRamp(80, kBase, 1);  // the limit stops sampling after 100 records
  take();
  ASSERT_TRUE(decoder.finished());
  EXPECT_EQ(next_tick, 100u);
  wire::LogTrailer t;
  ASSERT_EQ(wire::Decode(wire::PayloadOf(in), t), Status::kOk);
  EXPECT_EQ(t.first_record, 12u);
  EXPECT_EQ(t.record_count, 88u);
  EXPECT_EQ(t.records_written, 100u);
  EXPECT_EQ(t.acq_state, wire::AcqState::kDone);
}

TEST(CoreLog, BusyLinkLosesNothing) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Config(wire::kAllChannelsMask, 1)), Status::kOk);
  h.EmitRamp(30, kBase, 1);
  h.link.in_busy = true;
  wire::Report request{};
  std::array<std::uint8_t, wire::LogReadRequest::kBytes> p{};
  wire::Encode(wire::LogReadRequest{}, p);
  ASSERT_EQ(wire::BuildReport(Command::kLogRead, 9, 0, 0, Status::kOk, p, request), Status::kOk);
  h.link.Push(request);
  for (int i = 0; i < 5; ++i) h.core.Poll();
  EXPECT_EQ(h.link.pending_out(), 0u);
  h.link.in_busy = false;
  h.Drain();
  wire::StreamDecoder decoder(Command::kLogRead, 9);
  wire::Report in{};
  wire::StreamDecoder::Event last = wire::StreamDecoder::Event::kError;
  while (h.link.Pop(in)) last = decoder.Feed(in).event;
  EXPECT_EQ(last, wire::StreamDecoder::Event::kEnd);
  EXPECT_EQ(decoder.data_reports(), 10u);  // 30 records, three per report
}

}  // namespace
}  // namespace vibid::fw
