// Every payload against the golden reports of scripts/golden/wire_vectors.py: encoding the values
// written out here must give the golden bytes, and decoding the golden bytes must give these
// values back (hand-decoded from the layouts in commands.hpp).
#include "vibid/shared/wire/commands.hpp"

#include <gtest/gtest.h>

#include <array>

#include "golden_vectors.hpp"

namespace vibid::wire {
namespace {

using testing::GoldenReport;

InfoResponse ExpectedInfo() {
  InfoResponse v;
  v.fw_major = 0;
  v.fw_minor = 1;
  v.fw_patch = 2;
  v.board_id = BoardId::kStm32f405;
  v.build_id = 0xDEADBEEF;
  v.capabilities = 0x0F;
  v.sample_period_us = 200;
  v.min_sample_period_us = 100;
  v.log_capacity_bytes = 98304;
  v.link_reports_per_s = 1000;
  v.adc_bits = 12;
  v.channel_kind = {ChannelKind::kLoadCell,      ChannelKind::kLoadCell,
                    ChannelKind::kAccelerometer, ChannelKind::kAccelerometer,
                    ChannelKind::kEncoder,       ChannelKind::kEncoder};
  v.reset_cause = ResetCause::kWatchdog;
  v.cal_state = CalState::kCalibrated;
  v.cal_slot = 1;
  v.cal_crc = 0xCAFEF00D;
  v.overrun_count = 3;
  v.dropped_records = 17;
  return v;
}

TEST(Commands, InfoResponse) {
  Report out{};
  ASSERT_EQ(
      BuildReport(Command::kGetInfo, 0x0102, 0, kFlagResponse, Status::kOk, ExpectedInfo(), out),
      Status::kOk);
  EXPECT_TRUE(out == GoldenReport("info_response"));

  InfoResponse v;
  const Report golden = GoldenReport("info_response");
  ASSERT_EQ(Decode(PayloadOf(golden), v), Status::kOk);
  EXPECT_EQ(v.protocol_major, 2);
  EXPECT_EQ(v.protocol_minor, 0);
  EXPECT_EQ(v.fw_patch, 2);
  EXPECT_EQ(v.board_id, BoardId::kStm32f405);
  EXPECT_EQ(v.build_id, 0xDEADBEEFu);
  EXPECT_EQ(v.sample_period_us, 200u);
  EXPECT_EQ(v.log_capacity_bytes, 98304u);
  EXPECT_EQ(v.link_reports_per_s, 1000);
  EXPECT_EQ(v.adc_bits, 12);
  EXPECT_EQ(v.channel_kind[2], ChannelKind::kAccelerometer);
  EXPECT_EQ(v.channel_kind[5], ChannelKind::kEncoder);
  EXPECT_EQ(v.reset_cause, ResetCause::kWatchdog);
  EXPECT_EQ(v.cal_state, CalState::kCalibrated);
  EXPECT_EQ(v.cal_slot, 1);
  EXPECT_EQ(v.cal_crc, 0xCAFEF00Du);
  EXPECT_EQ(v.overrun_count, 3u);
  EXPECT_EQ(v.dropped_records, 17u);
  EXPECT_EQ(Decode(PayloadOf(golden).first(51), v), Status::kInvalidArgument);
}

TEST(Commands, StatusResponse) {
  StatusResponse s;
  s.acq_state = AcqState::kAcquiring;
  s.dob_running = 1;
  s.cal_state = CalState::kCalibrated;
  s.uptime_us = 123456789012u;
  s.ticks = 5000;
  s.records_written = 400;
  s.oldest_record = 100;
  s.overrun_count = 2;
  s.dropped_records = 7;
  s.rejected_requests = 1;
  s.saturation_count = 3;
  s.trigger_record = 40;
  s.cal_sequence = 9;
  Report out{};
  ASSERT_EQ(BuildReport(Command::kGetStatus, 0xFFFF, 0, kFlagResponse, Status::kOk, s, out),
            Status::kOk);
  EXPECT_TRUE(out == GoldenReport("status_response"));

  StatusResponse v;
  ASSERT_EQ(Decode(PayloadOf(GoldenReport("status_response")), v), Status::kOk);
  EXPECT_EQ(v.acq_state, AcqState::kAcquiring);
  EXPECT_EQ(v.uptime_us, 123456789012u);
  EXPECT_EQ(v.oldest_record, 100u);
  EXPECT_EQ(v.trigger_record, 40u);
  EXPECT_EQ(v.flash_errors, 0u);
}

TEST(Commands, AcqConfigure) {
  AcqConfigureRequest a;
  a.sample_period_us = 200;
  a.channel_mask = 0b100011;
  a.flags = kAcqFlagLogDob | kAcqFlagStream;
  a.decimation = 5;
  a.trigger_mode = TriggerMode::kRising;
  a.trigger_channel = 1;
  a.trigger_threshold = 429496730;  // 0.2 of full scale in Q31
  a.pretrigger_records = 250;
  a.record_limit = 10000;
  Report out{};
  ASSERT_EQ(BuildReport(Command::kAcqConfigure, 0x0A0B, 0, 0, Status::kOk, a, out), Status::kOk);
  EXPECT_TRUE(out == GoldenReport("acq_configure_request"));

  AcqConfigureRequest v;
  Report golden = GoldenReport("acq_configure_request");
  ASSERT_EQ(Decode(PayloadOf(golden), v), Status::kOk);
  EXPECT_EQ(v.sample_period_us, 200u);
  EXPECT_EQ(v.channel_mask, 0b100011);
  EXPECT_EQ(v.decimation, 5);
  EXPECT_EQ(v.trigger_mode, TriggerMode::kRising);
  EXPECT_EQ(v.trigger_threshold, 429496730);
  EXPECT_EQ(v.pretrigger_records, 250u);
  EXPECT_EQ(v.record_limit, 10000u);
  golden[kOffPayload + 8] = 3;  // no such trigger mode
  EXPECT_EQ(Decode(PayloadOf(golden), v), Status::kInvalidArgument);

  ASSERT_EQ(BuildReport(Command::kAcqConfigure, 0x0A0B, 0, kFlagResponse, Status::kOk,
                        AcqConfigureResponse{.record_bytes = 12, .capacity_records = 6144}, out),
            Status::kOk);
  EXPECT_TRUE(out == GoldenReport("acq_configure_response"));
}

TEST(Commands, LatestResponse) {
  LatestResponse l;
  l.tick = 42;
  l.calibrated = {1, -2, 3, -4, 5, -6};
  l.d_hat = 99;
  l.acq_state = AcqState::kAcquiring;
  l.dob_running = 1;
  Report out{};
  ASSERT_EQ(BuildReport(Command::kReadLatest, 3, 0, kFlagResponse, Status::kOk, l, out),
            Status::kOk);
  EXPECT_TRUE(out == GoldenReport("latest_response"));
  LatestResponse v;
  ASSERT_EQ(Decode(PayloadOf(out), v), Status::kOk);
  EXPECT_EQ(v.calibrated[5], -6);
  EXPECT_EQ(v.d_hat, 99);
}

TEST(Commands, LogReadAndCalibrationSmallPayloads) {
  Report out{};
  ASSERT_EQ(BuildReport(Command::kLogRead, 0x7777, 0, 0, Status::kOk,
                        LogReadRequest{.first_record = 10, .max_records = 5}, out),
            Status::kOk);
  EXPECT_TRUE(out == GoldenReport("log_read_request"));

  ASSERT_EQ(BuildReport(Command::kCalCommit, 0x0C0D, 0, kFlagResponse, Status::kOk,
                        CalCommitResponse{.slot = 1, .sequence = 8}, out),
            Status::kOk);
  EXPECT_TRUE(out == GoldenReport("cal_commit_response"));

  ASSERT_EQ(
      BuildReport(Command::kDobControl, 9, 0, 0, Status::kOk, DobControlRequest{.run = 1}, out),
      Status::kOk);
  EXPECT_TRUE(out == GoldenReport("dob_control_request"));
  DobControlRequest d;
  const std::array<std::uint8_t, 1> two{2};
  EXPECT_EQ(Decode(two, d), Status::kInvalidArgument);
}

TEST(Commands, ScenarioRequest) {
  ScenarioRequest s;
  const char name[] = "shaker";
  for (std::size_t i = 0; i + 1 < sizeof(name); ++i) s.name[i] = name[i];
  s.params = {16.0f, 2.5f, 0.0f, -1.0f};
  Report out{};
  ASSERT_EQ(BuildReport(Command::kSelectScenario, 0x70, 0, 0, Status::kOk, s, out), Status::kOk);
  EXPECT_TRUE(out == GoldenReport("scenario_request"));

  ScenarioRequest v;
  Report golden = GoldenReport("scenario_request");
  ASSERT_EQ(Decode(PayloadOf(golden), v), Status::kOk);
  EXPECT_EQ(v.name[5], 'r');
  EXPECT_EQ(v.name[6], '\0');
  EXPECT_EQ(v.params[0], 16.0f);
  EXPECT_EQ(v.params[3], -1.0f);
  golden[kOffPayload + 8] = 'x';  // text after the terminating NUL
  EXPECT_EQ(Decode(PayloadOf(golden), v), Status::kInvalidArgument);
}

TEST(Commands, InjectFrames) {
  InjectFramesRequest f;
  f.frame_count = 2;
  f.raw[0] = {1, 2, 3, 4, -5, -6};
  f.raw[1] = {2047, 2048, 4095, 0, INT32_MAX, INT32_MIN};
  std::array<std::uint8_t, InjectFramesRequest::kBytes> bytes{};
  Encode(f, bytes);
  Report out{};
  ASSERT_EQ(BuildReport(Command::kInjectFrames, 0x71, 0, 0, Status::kOk,
                        std::span<const std::uint8_t>(bytes).first(EncodedSize(f)), out),
            Status::kOk);
  EXPECT_TRUE(out == GoldenReport("inject_frames_request"));

  InjectFramesRequest v;
  ASSERT_EQ(Decode(PayloadOf(out), v), Status::kOk);
  EXPECT_EQ(v.frame_count, 2);
  EXPECT_EQ(v.raw[1][5], INT32_MIN);
  EXPECT_EQ(Decode(PayloadOf(out).first(28), v), Status::kInvalidArgument);  // count says 2
}

TEST(Commands, NamesAndPortRange) {
  EXPECT_STREQ(CommandName(0x24), "log-read");
  EXPECT_STREQ(CommandName(0x99), "unknown");
  EXPECT_TRUE(IsPortCommand(static_cast<std::uint8_t>(Command::kSelectScenario)));
  EXPECT_FALSE(IsPortCommand(static_cast<std::uint8_t>(Command::kLogRead)));
}

}  // namespace
}  // namespace vibid::wire
