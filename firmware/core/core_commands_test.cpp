// Every command of the server, and every refusal, through the report link of a fake port.
#include <gtest/gtest.h>

#include <array>

#include "core_harness.hpp"
#include "vibid/fw/version.hpp"
#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::fw {
namespace {

using testing::CoreHarness;
using testing::Response;
using wire::Command;

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
  const std::array<std::uint8_t, 1> unknown{2};
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
    if (request.empty()) return Status::kInvalidArgument;
    response[0] = static_cast<std::uint8_t>(request[0] + 1);
    response_length = 1;
    return Status::kOk;
  }
  std::uint8_t last_command = 0;
};

TEST(CoreCommands, PortCommandsGoToThePortHandler) {
  CoreHarness without;
  const std::array<std::uint8_t, 1> one{41};
  EXPECT_EQ(without.Request(Command::kSelectScenario, one).status(), Status::kUnimplemented);

  EchoPortCommands handler;
  CoreHarness h(&handler);
  Response r = h.Request(Command::kSelectScenario, one);
  ASSERT_EQ(r.status(), Status::kOk);
  EXPECT_EQ(handler.last_command, static_cast<std::uint8_t>(Command::kSelectScenario));
  ASSERT_EQ(r.payload().size(), 1u);
  EXPECT_EQ(r.payload()[0], 42);
  EXPECT_EQ(h.Request(Command::kInjectFrames).status(), Status::kInvalidArgument);
}

TEST(CoreCommands, AcqConfigureValidatesEveryField) {
  CoreHarness h;
  struct Case {
    const char* what;
    wire::AcqConfigureRequest config;
    Status expected;
  };
  auto with = [](auto edit) {
    wire::AcqConfigureRequest c = Immediate();
    edit(c);
    return c;
  };
  const Case cases[] = {
      {"period too short", with([](auto& c) { c.sample_period_us = 99; }),
       Status::kInvalidArgument},
      {"period too long", with([](auto& c) { c.sample_period_us = 1000001; }),
       Status::kInvalidArgument},
      {"no channel", with([](auto& c) { c.channel_mask = 0; }), Status::kInvalidArgument},
      {"seventh channel", with([](auto& c) { c.channel_mask = 0x41; }), Status::kInvalidArgument},
      {"unknown flag", with([](auto& c) { c.flags = 0x80; }), Status::kInvalidArgument},
      {"decimation 0", with([](auto& c) { c.decimation = 0; }), Status::kInvalidArgument},
      {"decimation too big", with([](auto& c) { c.decimation = 2000; }), Status::kInvalidArgument},
      {"decimation the decimator lacks", with([](auto& c) { c.decimation = 3; }),
       Status::kInvalidArgument},
      {"immediate with pre-trigger", with([](auto& c) { c.pretrigger_records = 1; }),
       Status::kInvalidArgument},
      {"immediate with threshold", with([](auto& c) { c.trigger_threshold = 5; }),
       Status::kInvalidArgument},
      {"trigger on an accelerometer", with([](auto& c) {
         c.trigger_mode = wire::TriggerMode::kRising;
         c.trigger_channel = 2;
       }),
       Status::kInvalidArgument},
      // Six channels, no d_hat: 16-byte records, 20 with the tick in the log: 2048 / 20 = 102
      // fit; 102 pre-trigger records would leave no room for the trigger record.
      {"pre-trigger fills the log", with([](auto& c) {
         c.trigger_mode = wire::TriggerMode::kFalling;
         c.trigger_channel = 1;
         c.pretrigger_records = 102;
       }),
       Status::kOutOfRange},
      {"d_hat without a filter", with([](auto& c) { c.flags = wire::kAcqFlagLogDob; }),
       Status::kFailedPrecondition},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(h.Request(Command::kAcqConfigure, c.config).status(), c.expected) << c.what;
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
  EXPECT_EQ(h.Request(Command::kAcqStart).status(), Status::kFailedPrecondition);  // unconfigured
  EXPECT_EQ(h.Request(Command::kAcqStop).status(), Status::kOk);                   // idempotent
  ASSERT_EQ(h.StartAcquisition(Immediate()), Status::kOk);
  EXPECT_TRUE(h.fake.frames.running());
  EXPECT_EQ(h.fake.frames.period_us, 200u);
  EXPECT_EQ(h.Request(Command::kAcqStart).status(), Status::kFailedPrecondition);
  EXPECT_EQ(h.Request(Command::kAcqConfigure, Immediate()).status(), Status::kFailedPrecondition);
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
  EXPECT_EQ(h.Request(Command::kCalCommit).status(),
            Status::kFailedPrecondition);                                        // nothing staged
  EXPECT_EQ(h.Request(Command::kCalGet).status(), Status::kFailedPrecondition);  // uncalibrated
  const std::array<std::uint8_t, 52> chunk{};
  EXPECT_EQ(h.Request(Command::kCalPutData, chunk).status(), Status::kFailedPrecondition);
  EXPECT_EQ(
      h.Request(Command::kCalPutBegin, wire::CalPutBeginRequest{.record_bytes = 836, .crc32 = 0})
          .status(),
      Status::kVersionMismatch);
}

TEST(CoreCommands, LogReadRefusals) {
  CoreHarness h;
  const wire::LogReadRequest from0{.first_record = 0, .max_records = 0};
  EXPECT_EQ(h.Request(Command::kLogRead, from0).status(), Status::kFailedPrecondition);
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
  EXPECT_EQ(h.Request(Command::kDobControl, wire::DobControlRequest{.run = 1}).status(),
            Status::kFailedPrecondition);
  const std::array<std::uint8_t, 1> two{2};
  EXPECT_EQ(h.Request(Command::kDobControl, two).status(), Status::kInvalidArgument);
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

}  // namespace
}  // namespace vibid::fw
