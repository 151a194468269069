// Every command of the server, and every refusal, through the report link of a fake port.
#include <gtest/gtest.h>

#include <array>
#include <optional>

#include "core_harness.hpp"
#include "test_records.hpp"
#include "vibid/fw/version.hpp"
#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/refusal.hpp"

namespace vibid::fw {
namespace {

using testing::CoreHarness;
using testing::Response;
using wire::Command;

/// The reason a refusal names (protocol 2.1: every refusal carries one).
wire::Refusal ReasonOf(const Response& r) {
  wire::Refusal why;
  EXPECT_EQ(r.payload().size(), wire::Refusal::kBytes) << "a refusal names its reason";
  EXPECT_EQ(wire::Decode(r.payload(), why), Status::kOk);
  return why;
}

wire::AcqConfigureRequest Immediate() {
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;
  c.channel_mask = wire::kAllChannelsMask;
  c.decimation = 1;
  return c;
}

TEST(CoreCommands, PingEchoesPayloadAndToken) {
  CoreHarness h;
  const std::array<std::uint8_t, 3> payload{1, 2, 3};
  const Response r = h.Request(Command::kPing, payload);
  ASSERT_TRUE(r.received);
  EXPECT_EQ(r.status(), Status::kOk);
  EXPECT_EQ(r.header.token, h.last_token);
  EXPECT_EQ(r.header.flags, wire::kFlagResponse);
  EXPECT_EQ(r.header.command, static_cast<std::uint8_t>(Command::kPing));
  ASSERT_EQ(r.payload().size(), 3u);
  EXPECT_EQ(r.payload()[2], 3);
}

TEST(CoreCommands, GetInfoDescribesTheBoard) {
  CoreHarness h;
  EXPECT_EQ(h.core.Boot(), Status::kDataLoss);  // blank flash
  const Response r = h.Request(Command::kGetInfo);
  ASSERT_EQ(r.status(), Status::kOk);
  wire::InfoResponse board_info;
  ASSERT_EQ(wire::Decode(r.payload(), board_info), Status::kOk);
  EXPECT_EQ(board_info.protocol_major, wire::kProtocolMajor);
  EXPECT_EQ(board_info.fw_major, CurrentFirmwareVersion().major);
  EXPECT_EQ(board_info.fw_minor, CurrentFirmwareVersion().minor);
  EXPECT_EQ(board_info.build_id, BuildId());
  EXPECT_EQ(board_info.board_id, wire::BoardId::kHostTest);
  EXPECT_EQ(board_info.capabilities, wire::kCapDfu | wire::kCapForceTrigger | wire::kCapDob);
  EXPECT_EQ(board_info.sample_period_us, Core::kDefaultSamplePeriodUs);
  EXPECT_EQ(board_info.log_capacity_bytes, CoreHarness::kLogBytes);
  EXPECT_EQ(board_info.channel_kind[0], wire::ChannelKind::kLoadCell);
  EXPECT_EQ(board_info.channel_kind[3], wire::ChannelKind::kAccelerometer);
  EXPECT_EQ(board_info.channel_kind[4], wire::ChannelKind::kEncoder);
  EXPECT_EQ(board_info.reset_cause, wire::ResetCause::kPowerOn);
  EXPECT_EQ(board_info.cal_state, wire::CalState::kUncalibrated);
  EXPECT_EQ(board_info.cal_slot, wire::kNoSlot);
  EXPECT_EQ(board_info.cal_crc, 0u);
}

TEST(CoreCommands, GetInfoPageGivesTheSamplingInstants) {
  CoreHarness h;
  const std::array<std::uint8_t, 1> page{wire::kInfoPageSampling};
  const Response r = h.Request(Command::kGetInfo, page);
  ASSERT_EQ(r.status(), Status::kOk);
  wire::SamplingInfoResponse s;
  ASSERT_EQ(wire::Decode(r.payload(), s), Status::kOk);
  // force1, acc1, acc2 and the encoders at 56 ADC clocks of 21 MHz (2666.7 ns), force2 one
  // 68-clock conversion later (124 clocks, 5904.8 ns) (board_profile.hpp).
  EXPECT_EQ(s.sample_instant_ns,
            (std::array<std::uint32_t, wire::kChannelCount>{2667, 5905, 2667, 2667, 2667, 2667}));
  const std::array<std::uint8_t, 1> unknown{5};  // pages 1 to 4 exist
  EXPECT_EQ(h.Request(Command::kGetInfo, unknown).status(), Status::kInvalidArgument);
  const std::array<std::uint8_t, 2> longer{1, 0};
  EXPECT_EQ(h.Request(Command::kGetInfo, longer).status(), Status::kInvalidArgument);
}

TEST(CoreCommands, GetStatusReportsClockAndCounters) {
  CoreHarness h;
  h.fake.clock.now_us = 987654321;
  const Response r = h.Request(Command::kGetStatus);
  ASSERT_EQ(r.status(), Status::kOk);
  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(r.payload(), s), Status::kOk);
  EXPECT_EQ(s.uptime_us, 987654321u);
  EXPECT_EQ(s.acq_state, wire::AcqState::kIdle);
  EXPECT_EQ(s.trigger_record, wire::kNoRecord);
  EXPECT_EQ(s.rejected_requests, 0u);
}

TEST(CoreCommands, ResetHappensAfterTheAnswerLeaves) {
  CoreHarness h;
  h.link.in_busy = true;
  wire::Report request{};
  ASSERT_EQ(wire::BuildReport(Command::kReset, 5, 0, 0, Status::kOk, {}, request), Status::kOk);
  h.link.Push(request);
  h.core.Poll();
  EXPECT_EQ(h.fake.system.resets, 0);  // answer still waiting for the IN endpoint
  h.link.in_busy = false;
  h.core.Poll();
  EXPECT_EQ(h.fake.system.resets, 1);
  wire::Report answer{};
  ASSERT_TRUE(h.link.Pop(answer));
  wire::Header hdr;
  ASSERT_EQ(wire::DecodeHeader(answer, hdr), Status::kOk);
  EXPECT_EQ(hdr.status, Status::kOk);
  EXPECT_EQ(hdr.token, 5);
}

TEST(CoreCommands, EnterDfu) {
  CoreHarness h;
  EXPECT_EQ(h.Request(Command::kEnterDfu).status(), Status::kOk);
  EXPECT_EQ(h.fake.system.dfu_entries, 1);

  CoreHarness no_dfu;
  no_dfu.fake.system.capabilities = 0;
  EXPECT_EQ(no_dfu.Request(Command::kEnterDfu).status(), Status::kUnimplemented);
  EXPECT_EQ(no_dfu.fake.system.dfu_entries, 0);

  CoreHarness busy;
  ASSERT_EQ(busy.StartAcquisition(Immediate()), Status::kOk);
  EXPECT_EQ(busy.Request(Command::kEnterDfu).status(), Status::kFailedPrecondition);
  EXPECT_EQ(busy.fake.system.dfu_entries, 0);
}

TEST(CoreCommands, RefusesMalformedReports) {
  CoreHarness h;
  wire::Report r{};
  ASSERT_EQ(wire::BuildReport(Command::kPing, 0x4242, 0, 0, Status::kOk, {}, r), Status::kOk);

  wire::Report bad_magic = r;
  bad_magic[0] = 'X';
  Response a = h.Raw(bad_magic);
  EXPECT_EQ(a.status(), Status::kDataLoss);
  EXPECT_EQ(a.header.token, 0x4242);

  wire::Report other_major = r;
  other_major[wire::kOffProtocolMajor] = wire::kProtocolMajor + 1;
  a = h.Raw(other_major);
  EXPECT_EQ(a.status(), Status::kVersionMismatch);
  EXPECT_EQ(a.header.protocol_major, wire::kProtocolMajor);  // the device says what it speaks

  // One header byte off each.
  struct Malformed {
    const char* what;
    std::size_t offset;
    std::uint8_t value;
    Status status;
  };
  const Malformed cases[] = {
      {"response flag", wire::kOffFlags, wire::kFlagResponse, Status::kInvalidArgument},
      {"reserved byte", wire::kOffReserved, 1, Status::kInvalidArgument},
      {"payload longer than a report", wire::kOffPayloadLength, 53, Status::kInvalidArgument},
      {"sequence on a request", wire::kOffSequence, 1, Status::kInvalidArgument},
      {"unknown command", wire::kOffCommand, 0x55, Status::kUnimplemented},
  };
  for (const Malformed& m : cases) {
    wire::Report bad = r;
    bad[m.offset] = m.value;
    EXPECT_EQ(h.Raw(bad).status(), m.status) << m.what;
  }

  EXPECT_EQ(h.core.rejected_requests(), 7u);
  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  EXPECT_EQ(s.rejected_requests, 7u);
}

TEST(CoreCommands, RefusesPayloadOnEmptyCommands) {
  CoreHarness h;
  const std::array<std::uint8_t, 1> one{0};
  for (const Command c : {Command::kGetInfo, Command::kGetStatus, Command::kReset,
                          Command::kEnterDfu, Command::kCalCommit, Command::kCalGet,
                          Command::kAcqStart, Command::kAcqStop, Command::kReadLatest}) {
    EXPECT_EQ(h.Request(c, one).status(), Status::kInvalidArgument)
        << wire::CommandName(static_cast<std::uint8_t>(c));
  }
  EXPECT_EQ(h.fake.system.resets, 0);
  for (const Command c : {Command::kCalPutBegin, Command::kAcqConfigure, Command::kLogRead}) {
    EXPECT_EQ(h.Request(c, one).status(), Status::kInvalidArgument);
  }
}

class EchoPortCommands final : public PortCommandHandler {
 public:
  Status HandlePortCommand(std::uint8_t command, std::span<const std::uint8_t> request,
                           std::span<std::uint8_t, wire::kMaxPayload> response,
                           std::size_t& response_length) override {
    last_command = command;
    if (refusal) {
      wire::Encode(*refusal, response);
      response_length = wire::Refusal::kBytes;
      return Status::kInvalidArgument;
    }
    if (request.empty()) return Status::kInvalidArgument;
    response[0] = static_cast<std::uint8_t>(request[0] + 1);
    response_length = 1;
    return Status::kOk;
  }
  std::uint8_t last_command = 0;
  std::optional<wire::Refusal> refusal;  // set: refuse with this reason
};

TEST(CoreCommands, PortCommandsGoToThePortHandler) {
  CoreHarness without;
  const std::array<std::uint8_t, 1> one{41};
  const Response unknown = without.Request(Command::kSelectScenario, one);
  EXPECT_EQ(unknown.status(), Status::kUnimplemented);
  EXPECT_EQ(ReasonOf(unknown).reason, wire::Reason::kUnknownCommand);

  EchoPortCommands handler;
  CoreHarness h(&handler);
  Response r = h.Request(Command::kSelectScenario, one);
  ASSERT_EQ(r.status(), Status::kOk);
  EXPECT_EQ(handler.last_command, static_cast<std::uint8_t>(Command::kSelectScenario));
  ASSERT_EQ(r.payload().size(), 1u);
  EXPECT_EQ(r.payload()[0], 42);
  // A port refusal without a reason of its own is named from the status.
  const Response refused = h.Request(Command::kInjectFrames);
  EXPECT_EQ(refused.status(), Status::kInvalidArgument);
  EXPECT_EQ(ReasonOf(refused).reason, wire::Reason::kPortRefused);
  // A port refusal with a reason passes it on, detail included.
  handler.refusal = wire::Refusal{.reason = wire::Reason::kScenarioParameter, .detail = 2};
  const Response named = h.Request(Command::kSelectScenario, one);
  EXPECT_EQ(named.status(), Status::kInvalidArgument);
  EXPECT_EQ(ReasonOf(named).reason, wire::Reason::kScenarioParameter);
  EXPECT_EQ(ReasonOf(named).detail, 2u);
}

TEST(CoreCommands, AcqConfigureValidatesEveryField) {
  CoreHarness h;
  struct Case {
    const char* what;
    wire::AcqConfigureRequest config;
    Status expected;
    wire::Reason reason;
    std::uint32_t detail = 0;
  };
  auto with = [](auto edit) {
    wire::AcqConfigureRequest c = Immediate();
    edit(c);
    return c;
  };
  const Case cases[] = {
      {"period too short", with([](auto& c) { c.sample_period_us = 99; }), Status::kInvalidArgument,
       wire::Reason::kSamplePeriod, 100},
      {"period too long", with([](auto& c) { c.sample_period_us = 1000001; }),
       Status::kInvalidArgument, wire::Reason::kSamplePeriod, 100},
      {"no channel", with([](auto& c) { c.channel_mask = 0; }), Status::kInvalidArgument,
       wire::Reason::kChannelSelection},
      {"seventh channel", with([](auto& c) { c.channel_mask = 0x41; }), Status::kInvalidArgument,
       wire::Reason::kChannelSelection},
      {"unknown flag", with([](auto& c) { c.flags = 0x80; }), Status::kInvalidArgument,
       wire::Reason::kChannelSelection},
      {"decimation 0", with([](auto& c) { c.decimation = 0; }), Status::kInvalidArgument,
       wire::Reason::kDecimation, 1000},
      {"decimation too big", with([](auto& c) { c.decimation = 2000; }), Status::kInvalidArgument,
       wire::Reason::kDecimation, 1000},
      {"decimation the decimator lacks", with([](auto& c) { c.decimation = 3; }),
       Status::kInvalidArgument, wire::Reason::kDecimation, 1000},
      {"immediate with pre-trigger", with([](auto& c) { c.pretrigger_records = 1; }),
       Status::kInvalidArgument, wire::Reason::kTrigger},
      {"immediate with threshold", with([](auto& c) { c.trigger_threshold = 5; }),
       Status::kInvalidArgument, wire::Reason::kTrigger},
      {"trigger on an accelerometer", with([](auto& c) {
         c.trigger_mode = wire::TriggerMode::kRising;
         c.trigger_channel = 2;
       }),
       Status::kInvalidArgument, wire::Reason::kTrigger},
      // Six channels, no d_hat: 16-byte records, 20 with the tick in the log: 2048 / 20 = 102
      // fit; 102 pre-trigger records would leave no room for the trigger record.
      {"pre-trigger fills the log", with([](auto& c) {
         c.trigger_mode = wire::TriggerMode::kFalling;
         c.trigger_channel = 1;
         c.pretrigger_records = 102;
       }),
       Status::kOutOfRange, wire::Reason::kPretriggerTooLong, 102},
      {"d_hat without a filter", with([](auto& c) { c.flags = wire::kAcqFlagLogDob; }),
       Status::kFailedPrecondition, wire::Reason::kNoObserver},
  };
  for (const Case& c : cases) {
    const Response r = h.Request(Command::kAcqConfigure, c.config);
    EXPECT_EQ(r.status(), c.expected) << c.what;
    const wire::Refusal why = ReasonOf(r);
    EXPECT_EQ(why.reason, c.reason) << c.what;
    EXPECT_EQ(why.detail, c.detail) << c.what;
  }
  EXPECT_EQ(h.core.rejected_requests(), sizeof(cases) / sizeof(cases[0]));

  wire::AcqConfigureRequest ok = Immediate();
  ok.trigger_mode = wire::TriggerMode::kFalling;
  ok.trigger_channel = 1;
  ok.pretrigger_records = 101;
  const Response r = h.Request(Command::kAcqConfigure, ok);
  ASSERT_EQ(r.status(), Status::kOk);
  wire::AcqConfigureResponse answer;
  ASSERT_EQ(wire::Decode(r.payload(), answer), Status::kOk);
  EXPECT_EQ(answer.record_bytes, 16);
  EXPECT_EQ(answer.capacity_records, 102u);
}

TEST(CoreCommands, AcquisitionStateRules) {
  CoreHarness h;
  const Response unconfigured = h.Request(Command::kAcqStart);
  EXPECT_EQ(unconfigured.status(), Status::kFailedPrecondition);
  EXPECT_EQ(ReasonOf(unconfigured).reason, wire::Reason::kNotConfigured);
  EXPECT_EQ(h.Request(Command::kAcqStop).status(), Status::kOk);  // idempotent
  ASSERT_EQ(h.StartAcquisition(Immediate()), Status::kOk);
  EXPECT_TRUE(h.fake.frames.running());
  EXPECT_EQ(h.fake.frames.period_us, 200u);
  EXPECT_EQ(h.Request(Command::kAcqStart).status(), Status::kFailedPrecondition);
  const Response busy = h.Request(Command::kAcqConfigure, Immediate());
  EXPECT_EQ(busy.status(), Status::kFailedPrecondition);
  EXPECT_EQ(ReasonOf(busy).reason, wire::Reason::kBusySampling);
  h.EmitRamp(3, {}, 1);
  const Response stop = h.Request(Command::kAcqStop);
  ASSERT_EQ(stop.status(), Status::kOk);
  wire::AcqStopResponse stopped;
  ASSERT_EQ(wire::Decode(stop.payload(), stopped), Status::kOk);
  EXPECT_EQ(stopped.records_written, 3u);
  EXPECT_FALSE(h.fake.frames.running());

  // A port that cannot produce the period refuses the start; nothing is left running.
  h.fake.frames.start_status = Status::kInvalidArgument;
  EXPECT_EQ(h.Request(Command::kAcqStart).status(), Status::kInvalidArgument);
  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  EXPECT_EQ(s.acq_state, wire::AcqState::kIdle);
}

TEST(CoreCommands, CalibrationRefusals) {
  CoreHarness h;
  const Response commit = h.Request(Command::kCalCommit);
  EXPECT_EQ(commit.status(), Status::kFailedPrecondition);
  EXPECT_EQ(ReasonOf(commit).reason, wire::Reason::kNothingStaged);
  const Response get = h.Request(Command::kCalGet);
  EXPECT_EQ(get.status(), Status::kFailedPrecondition);
  EXPECT_EQ(ReasonOf(get).reason, wire::Reason::kNotCalibrated);
  const std::array<std::uint8_t, 52> chunk{};
  const Response data = h.Request(Command::kCalPutData, chunk);
  EXPECT_EQ(data.status(), Status::kFailedPrecondition);
  EXPECT_EQ(ReasonOf(data).reason, wire::Reason::kUploadSequence);
  const Response begin =
      h.Request(Command::kCalPutBegin,
                wire::CalPutBeginRequest{.record_bytes = 876, .crc32 = 0});  // a version-2 record
  EXPECT_EQ(begin.status(), Status::kVersionMismatch);
  EXPECT_EQ(ReasonOf(begin).reason, wire::Reason::kRecordLength);
  EXPECT_EQ(ReasonOf(begin).detail, 1020u);  // kCalRecordBytes
}

TEST(CoreCommands, LogReadRefusals) {
  CoreHarness h;
  const wire::LogReadRequest from0{.first_record = 0, .max_records = 0};
  const Response none = h.Request(Command::kLogRead, from0);
  EXPECT_EQ(none.status(), Status::kFailedPrecondition);
  EXPECT_EQ(ReasonOf(none).reason, wire::Reason::kNoLog);
  ASSERT_EQ(h.StartAcquisition(Immediate()), Status::kOk);
  h.EmitRamp(5, {}, 1);
  EXPECT_EQ(h.Request(Command::kLogRead, wire::LogReadRequest{.first_record = 6}).status(),
            Status::kOutOfRange);
  h.Request(Command::kLogRead, wire::LogReadRequest{.first_record = 3});  // releases 0..2
  h.Drain();
  // Released but not overwritten: still served (kLogBytes holds 73 of these records).
  EXPECT_EQ(h.Request(Command::kLogRead, wire::LogReadRequest{.first_record = 2}).status(),
            Status::kOk);
  h.Drain();
  EXPECT_EQ(h.core.log().released(), 3u);
}

TEST(CoreCommands, DobControlWithoutFilter) {
  CoreHarness h;
  const Response run = h.Request(Command::kDobControl, wire::DobControlRequest{.run = 1});
  EXPECT_EQ(run.status(), Status::kFailedPrecondition);
  EXPECT_EQ(ReasonOf(run).reason, wire::Reason::kNoObserver);
  const std::array<std::uint8_t, 1> two{2};
  const Response bad = h.Request(Command::kDobControl, two);
  EXPECT_EQ(bad.status(), Status::kInvalidArgument);
  EXPECT_EQ(ReasonOf(bad).reason, wire::Reason::kPayloadLength);
}

TEST(CoreCommands, ReadLatestShowsCalibratedFrame) {
  CoreHarness h;
  Response r = h.Request(Command::kReadLatest);
  ASSERT_EQ(r.status(), Status::kOk);
  wire::LatestResponse latest;
  ASSERT_EQ(wire::Decode(r.payload(), latest), Status::kOk);
  EXPECT_EQ(latest.tick, 0u);
  ASSERT_EQ(h.StartAcquisition(Immediate()), Status::kOk);
  h.EmitRamp(4, {10, 20, 30, 40, -50, 60}, 2);
  r = h.Request(Command::kReadLatest);
  ASSERT_EQ(wire::Decode(r.payload(), latest), Status::kOk);
  // Uncalibrated: calibrated value = raw count. Frame 3: base + 3 * 2.
  EXPECT_EQ(latest.tick, 3u);
  EXPECT_EQ(latest.calibrated[0], 16);
  EXPECT_EQ(latest.calibrated[4], -44);
  EXPECT_EQ(latest.acq_state, wire::AcqState::kAcquiring);
}

// get-clips: a sample counts on its channel when its code sits at an end of the 12-bit ADC's
// range (0 or 4095) or its calibration saturates; encoders only by saturation.
TEST(CoreCommands, ClipsAreCountedPerChannel) {
  CoreHarness h;
  ASSERT_EQ(h.StartAcquisition(Immediate()), Status::kOk);
  // force1 at the top code, force2 at 0, acc1 mid-scale, acc2 beyond the top (a converter the
  // board cannot have), encoders at INT32 extremes (uncalibrated: identity, no saturation).
  const std::array<std::array<std::int32_t, wire::kChannelCount>, 3> frames{{
      {4095, 0, 2048, 65535, INT32_MAX, INT32_MIN},
      {4094, 1, 2048, 4095, 0, 0},
      {4095, 2, 2048, 100, 0, 0},
  }};
  for (const auto& f : frames) h.fake.frames.Emit(f);
  const Response r = h.Request(Command::kGetClips);
  ASSERT_EQ(r.status(), Status::kOk);
  wire::ClipResponse clips;
  ASSERT_EQ(wire::Decode(r.payload(), clips), Status::kOk);
  EXPECT_EQ(clips.ticks, 3u);
  EXPECT_EQ(clips.clipped, (std::array<std::uint32_t, wire::kChannelCount>{2, 1, 0, 2, 0, 0}));
  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  EXPECT_EQ(s.saturation_count, 5u);  // the sum over the channels; no observer
  // A new acquisition starts the counts again.
  ASSERT_EQ(h.Request(Command::kAcqStop).status(), Status::kOk);
  ASSERT_EQ(h.StartAcquisition(Immediate()), Status::kOk);
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetClips).payload(), clips), Status::kOk);
  EXPECT_EQ(clips.ticks, 0u);
  EXPECT_EQ(clips.clipped, (std::array<std::uint32_t, wire::kChannelCount>{}));
}

// A unipolar load cell calibrated with its zero at code 0 rests there: code 0 is no clip on it,
// the top code still is; a channel with its zero mid-scale still clips at 0.
TEST(CoreCommands, AUnipolarChannelRestingAtCodeZeroDoesNotClip) {
  CoreHarness h;
  (void)h.core.Boot();
  wire::CalibrationRecord record = testing::TestRecord(3);
  record.channels[1].offset_counts = 0;  // force2: 0 N at code 0, 4095 counts of push
  ASSERT_EQ(h.Upload(testing::Encoded(record)), Status::kOk);
  ASSERT_EQ(h.Request(Command::kCalCommit).status(), Status::kOk);
  ASSERT_EQ(h.StartAcquisition(Immediate()), Status::kOk);
  for (int k = 0; k < 10; ++k) h.fake.frames.Emit({2048, 0, 0, 2048, 0, 0});
  h.fake.frames.Emit({2048, 4095, 2048, 2048, 0, 0});
  wire::ClipResponse clips;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetClips).payload(), clips), Status::kOk);
  EXPECT_EQ(clips.ticks, 11u);
  // force2 only at its top code; acc1 (zero at 2048) on each of its ten samples at code 0.
  EXPECT_EQ(clips.clipped, (std::array<std::uint32_t, wire::kChannelCount>{0, 1, 10, 0, 0, 0}));
}

// read-latest after an acquisition holds its last frame: frames the port delivers after the
// record limit (before the main loop stops it) do not replace it.
TEST(CoreCommands, ReadLatestKeepsTheLastFrameOfTheAcquisition) {
  CoreHarness h;
  wire::AcqConfigureRequest c = Immediate();
  c.record_limit = 3;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
  h.EmitRamp(5, {100, 100, 100, 100, 100, 100}, 1);  // ticks 0..4; the limit is reached at 2
  wire::LatestResponse latest;
  ASSERT_EQ(wire::Decode(h.Request(Command::kReadLatest).payload(), latest), Status::kOk);
  EXPECT_EQ(latest.acq_state, wire::AcqState::kDone);
  EXPECT_EQ(latest.tick, 2u);
  EXPECT_EQ(latest.calibrated[0], 102);
  wire::StatusResponse s;
  ASSERT_EQ(wire::Decode(h.Request(Command::kGetStatus).payload(), s), Status::kOk);
  EXPECT_EQ(s.ticks, 3u);  // the host's "last frame" is tick ticks - 1
}

}  // namespace
}  // namespace vibid::fw
