// The DOB in the sampling pipeline: an uploaded filter runs on every frame and its logged d_hat
// equals a host-side replay (wire::ScaleChannel + the same kernel on the logged raw values)
// bit for bit; rate and state rules are enforced.
#include <gtest/gtest.h>

#include <array>

#include "core_harness.hpp"
#include "test_filter.hpp"
#include "test_records.hpp"
#include "vibid/shared/fixed/dob_filter.hpp"
#include "vibid/shared/wire/refusal.hpp"

namespace vibid::fw {
namespace {

using testing::CoreHarness;
using testing::Encoded;
using testing::PulledLog;
using testing::PullLog;
using wire::Command;

// TestRecord(1) with the test filter on force 1 (channel 0, 100 N) and accelerometer 2
// (channel 3, 490 m/s^2), both on mass 1.
wire::CalibrationRecord RecordWithDob() {
  wire::CalibrationRecord r = testing::TestRecord(1);
  wire::testing::AttachFilter(r, wire::testing::TestFilter(5000), 0, 3);
  return r;
}

void InstallDob(CoreHarness& h) {
  ASSERT_EQ(h.Upload(Encoded(RecordWithDob())), Status::kOk);
  ASSERT_EQ(h.Request(Command::kCalCommit).status(), Status::kOk);
}

// A deterministic, non-trivial excitation: force and acceleration swing over most of the
// converter range with different periods.
std::array<std::int32_t, wire::kChannelCount> Frame(std::int32_t k) {
  const std::int32_t force = 2048 + ((k * 37) % 1500) - 750;
  const std::int32_t accel = 2048 + ((k * 101) % 1800) - 900;
  return {force, 2048, 2048, accel, k, -k};
}

// What the host does with a log: scale the raw values, route them, step the same kernel.
class HostReplay {
 public:
  HostReplay() : record_(RecordWithDob()) {
    fixed::FilterDescription description;
    (void)fixed::DecodeDescription(record_.dob, description);
    initialised_ = filter_.Init(description) == Status::kOk;
  }
  bool initialised() const { return initialised_; }
  std::uint32_t clips() const { return clips_; }
  std::int32_t Step(const std::array<std::int32_t, wire::kChannelCount>& raw) {
    return filter_.Step({wire::ScaleChannel(raw[0], record_.channels[0], clips_),
                         wire::ScaleChannel(raw[3], record_.channels[3], clips_), 0});
  }

 private:
  wire::CalibrationRecord record_;
  fixed::DobFilter filter_;
  bool initialised_ = false;
  std::uint32_t clips_ = 0;
};

TEST(CoreDob, LoggedDhatEqualsHostReplayBitForBit) {
  CoreHarness h;
  InstallDob(h);
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;   // 5 kHz, the filter's rate
  c.channel_mask = 0b001001;  // force 1, accelerometer 2
  c.flags = wire::kAcqFlagLogDob;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
  constexpr std::int32_t kFrames = 120;  // 8-byte records, 12 stored: 170 fit in the 2 KiB log
  for (std::int32_t k = 0; k < kFrames; ++k) h.fake.frames.Emit(Frame(k));

  const PulledLog log = PullLog(h, 0, 0);
  ASSERT_EQ(log.status, Status::kOk);
  ASSERT_EQ(log.count, static_cast<std::size_t>(kFrames));
  EXPECT_EQ(log.trailer.record_bytes, 8);

  // Host replay from the logged raw values only.
  HostReplay replay;
  ASSERT_TRUE(replay.initialised());
  std::size_t nonzero = 0;
  for (std::size_t n = 0; n < log.count; ++n) {
    const wire::LogRecord& rec = log.records[n];
    // Undecimated converter values are whole codes in 12.4: the code is the value >> 4.
    std::array<std::int32_t, wire::kChannelCount> raw = rec.raw;
    for (std::size_t ch = 0; ch < 4; ++ch) {
      EXPECT_EQ(raw[ch] % 16, 0);
      raw[ch] /= 16;
    }
    EXPECT_EQ(rec.d_hat, replay.Step(raw)) << "frame " << n;
    if (rec.d_hat != 0) ++nonzero;
  }
  EXPECT_GT(nonzero, log.count / 2);  // the comparison is not between zeros
  EXPECT_EQ(replay.clips(), 0u);
}

TEST(CoreDob, RateMustMatchTheFilter) {
  CoreHarness h;
  InstallDob(h);
  wire::AcqConfigureRequest c;
  c.sample_period_us = 250;  // 4 kHz; the filter was discretized at 5 kHz
  c.channel_mask = 1;
  c.flags = wire::kAcqFlagLogDob;
  const testing::Response r = h.Request(Command::kAcqConfigure, c);
  EXPECT_EQ(r.status(), Status::kInvalidArgument);
  // The refusal names the cause and the observer's rate, for the host's way out.
  wire::Refusal why;
  ASSERT_EQ(wire::Decode(r.payload(), why), Status::kOk);
  EXPECT_EQ(why.reason, wire::Reason::kObserverRate);
  EXPECT_EQ(why.detail, 5000u);  // TestFilter(5000)
}

TEST(CoreDob, DobControlRunsItWithoutLogging) {
  CoreHarness h;
  InstallDob(h);
  ASSERT_EQ(h.Request(Command::kDobControl, wire::DobControlRequest{.run = 1}).status(),
            Status::kOk);
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;
  c.channel_mask = 1;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
  for (std::int32_t k = 0; k < 20; ++k) h.fake.frames.Emit(Frame(k));

  HostReplay replay;
  ASSERT_TRUE(replay.initialised());
  std::int32_t expected = 0;
  for (std::int32_t k = 0; k < 20; ++k) expected = replay.Step(Frame(k));
  wire::LatestResponse latest;
  ASSERT_EQ(wire::Decode(h.Request(Command::kReadLatest).payload(), latest), Status::kOk);
  EXPECT_EQ(latest.dob_running, 1);
  EXPECT_EQ(latest.d_hat, expected);
  EXPECT_NE(expected, 0);

  ASSERT_EQ(h.Request(Command::kDobControl, wire::DobControlRequest{.run = 0}).status(),
            Status::kOk);
  h.fake.frames.Emit(Frame(20));
  ASSERT_EQ(wire::Decode(h.Request(Command::kReadLatest).payload(), latest), Status::kOk);
  EXPECT_EQ(latest.dob_running, 0);
  EXPECT_EQ(latest.d_hat, 0);
}

TEST(CoreDob, FilterSurvivesRebootAndGoesWithAnUncalibratedRecord) {
  CoreHarness h;
  InstallDob(h);
  CoreHarness rebooted;
  rebooted.fake.flash = h.fake.flash;
  ASSERT_EQ(rebooted.core.Boot(), Status::kOk);
  EXPECT_EQ(rebooted.Request(Command::kDobControl, wire::DobControlRequest{.run = 1}).status(),
            Status::kOk);
  // A record without a filter replaces it: the DOB is gone.
  ASSERT_EQ(rebooted.Upload(Encoded(testing::TestRecord(2))), Status::kOk);
  ASSERT_EQ(rebooted.Request(Command::kCalCommit).status(), Status::kOk);
  EXPECT_EQ(rebooted.Request(Command::kDobControl, wire::DobControlRequest{.run = 1}).status(),
            Status::kFailedPrecondition);
}

}  // namespace
}  // namespace vibid::fw
