// The residual test in the sampling pipeline: the board runs it beside the observer on every
// frame, its statistic and trip tick equal a host-side replay (wire::ScaleChannel, the same
// observer and the same test on the same raw values) bit for bit, a residual whose power steps up
// trips the "model stale" flag within the windows the CUSUM's run length predicts, one that stays
// in control does not over a long run, and get-info's watch page reports all of it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "core_harness.hpp"
#include "test_filter.hpp"
#include "test_records.hpp"
#include "vibid/fw/sampler.hpp"
#include "vibid/shared/fixed/decimator.hpp"
#include "vibid/shared/fixed/dob_filter.hpp"
#include "vibid/shared/fixed/residual_cusum.hpp"
#include "vibid/shared/wire/watch_info.hpp"

namespace vibid::fw {
namespace {

using testing::CoreHarness;
using testing::Encoded;
using wire::Command;

constexpr std::uint32_t kWindow = 64;
constexpr double kK = 0.5;
// h for an in-control run length of about 10^5 windows (Siegmund's approximation at k = 0.5:
// ARL0 = (exp(2 k b) - 2 k b - 1) / (2 k^2), b = h + 1.166; 10 gives 1.4e5), so a few hundred
// windows in control trip with a probability near 0.3 %.
constexpr double kH = 10.0;

// Near-Gaussian converter noise around mid-scale (the sum of four xorshift32 uniforms), integer
// codes so every target sees the same frames.
class Noise {
 public:
  explicit Noise(std::uint32_t seed) : state_(seed) {}
  std::int32_t Code(double rms_codes) {
    double u = 0.0;
    for (int i = 0; i < 4; ++i) {
      state_ ^= state_ << 13;
      state_ ^= state_ >> 17;
      state_ ^= state_ << 5;
      u += static_cast<double>(state_) / 4294967296.0 - 0.5;
    }
    return 2048 + static_cast<std::int32_t>(std::lround(u * rms_codes * std::sqrt(3.0)));
  }

 private:
  std::uint32_t state_;
};

// Force 1 and accelerometer 2 feed the observer (as in core_dob_test), force 2 (channel 1) is the
// reference the test subtracts when asked to.
std::array<std::int32_t, wire::kChannelCount> Frame(Noise& noise, double rms_codes) {
  return {noise.Code(rms_codes), noise.Code(rms_codes), 2048, noise.Code(rms_codes), 0, 0};
}

wire::CalibrationRecord RecordWithDob() {
  wire::CalibrationRecord r = testing::TestRecord(1);
  wire::testing::AttachFilter(r, wire::testing::TestFilter(5000), 0, 3);
  return r;
}

// The host's side: the observer and the test replayed on the raw frames.
class Replay {
 public:
  explicit Replay(const wire::CalibrationRecord& record) : record_(record) {
    fixed::FilterDescription d;
    (void)fixed::DecodeDescription(record_.dob, d);
    EXPECT_EQ(filter_.Init(d), Status::kOk);
  }
  std::int32_t DHat(const std::array<std::int32_t, wire::kChannelCount>& raw) {
    std::uint32_t clips = 0;
    for (std::size_t c = 0; c < raw.size(); ++c)
      calibrated_[c] = wire::ScaleChannel(raw[c], record_.channels[c], clips);
    return filter_.Step({calibrated_[0], calibrated_[3], 0});
  }
  std::int32_t Calibrated(std::size_t channel) const { return calibrated_[channel]; }

 private:
  wire::CalibrationRecord record_;
  fixed::DobFilter filter_;
  std::array<std::int32_t, wire::kChannelCount> calibrated_{};
};

// The calibration day: d_hat's residual over `windows` windows of in-control frames (another
// seed than the run's), its scale put near 2^15 RMS and the window mean's mean and spread
// measured, then rounded to the kernel's parameters as the host's design does.
wire::CalibrationRecord RecordWithWatch(bool with_reference, double* spread_over_mean = nullptr) {
  wire::CalibrationRecord r = RecordWithDob();
  const double reference_ratio = with_reference ? 0.25 : 0.0;  // d_hat - 0.25 (50 N / 200 N) F2
  Replay day(r);
  Noise noise(0xC0FFEEu);
  std::vector<double> residual;
  for (std::uint32_t n = 0; n < 400 * kWindow; ++n) {
    const std::int32_t d_hat = day.DHat(Frame(noise, 200.0));
    residual.push_back(d_hat - reference_ratio * day.Calibrated(1));
  }
  double power = 0.0;
  for (const double v : residual) power += v * v;
  const double scale =
      std::min(0.5, std::ldexp(1.0, 15) / std::sqrt(power / static_cast<double>(residual.size())));
  std::vector<double> means;
  for (std::size_t w = 0; w + kWindow <= residual.size(); w += kWindow) {
    double sum = 0.0;
    for (std::size_t n = w; n < w + kWindow; ++n) sum += residual[n] * scale * residual[n] * scale;
    means.push_back(sum / kWindow);
  }
  double mu0 = 0.0;
  for (const double m : means) mu0 += m;
  mu0 /= static_cast<double>(means.size());
  double var = 0.0;
  for (const double m : means) var += (m - mu0) * (m - mu0);
  const double sigma0 = std::sqrt(var / static_cast<double>(means.size() - 1));
  if (spread_over_mean != nullptr) *spread_over_mean = sigma0 / mu0;

  fixed::ResidualCusumParams p;
  p.window_samples = kWindow;
  p.residual_gain = static_cast<std::int32_t>(std::lround(std::ldexp(scale, 32)));
  p.reference_gain =
      static_cast<std::int32_t>(std::lround(-std::ldexp(reference_ratio * scale, 32)));
  const double w_mu0 = kWindow * mu0;
  p.sum_shift = static_cast<std::uint8_t>(std::max(0, static_cast<int>(std::log2(w_mu0)) - 24));
  p.center = static_cast<std::int32_t>(std::lround(std::ldexp(w_mu0, -p.sum_shift)));
  const double unit = std::ldexp(1.0, 16 + p.sum_shift) / (kWindow * sigma0);
  int z_shift = 0;
  while (unit * std::ldexp(1.0, z_shift + 1) < 2147483647.0) ++z_shift;
  p.z_shift = static_cast<std::uint8_t>(z_shift);
  p.z_gain = static_cast<std::int32_t>(std::lround(std::ldexp(unit, z_shift)));
  p.k = static_cast<std::int32_t>(std::lround(kK * 65536));
  p.h = static_cast<std::int32_t>(std::lround(kH * 65536));
  r.flags = static_cast<std::uint8_t>(r.flags | wire::kCalFlagHasWatch);
  r.watch = p;
  r.watch_reference_channel = with_reference ? 1 : wire::kNoChannel;
  r.watch_in_control_arl_windows = 1.4e5f;
  return r;
}

void Install(CoreHarness& h, const wire::CalibrationRecord& r) {
  ASSERT_EQ(h.Upload(Encoded(r)), Status::kOk);
  ASSERT_EQ(h.Request(Command::kCalCommit).status(), Status::kOk);
}

void Start(CoreHarness& h) {
  ASSERT_EQ(h.Request(Command::kDobControl, wire::DobControlRequest{.run = 1}).status(),
            Status::kOk);
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;  // 5 kHz, the filter's rate
  c.channel_mask = 1;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
}

wire::WatchInfoResponse WatchPage(CoreHarness& h) {
  const testing::Response r =
      h.Request(Command::kGetInfo, wire::InfoPageRequest{.page = wire::kInfoPageWatch});
  EXPECT_EQ(r.status(), Status::kOk);
  wire::WatchInfoResponse page;
  EXPECT_EQ(wire::Decode(r.payload(), page), Status::kOk);
  return page;
}

TEST(CoreWatch, BoardEqualsTheHostReplayBitForBit) {
  const wire::CalibrationRecord record = RecordWithWatch(/*with_reference=*/true);
  CoreHarness h;
  Install(h, record);
  Start(h);
  Replay replay(record);
  fixed::ResidualCusum test;
  ASSERT_EQ(test.Init(record.watch), Status::kOk);
  Noise noise(0x1234567u);
  std::uint32_t trip_tick = 0;
  for (std::uint32_t n = 0; n < 60 * kWindow; ++n) {
    // The power steps up 4 times (the amplitude twice) after 30 windows.
    const auto raw = Frame(noise, n < 30 * kWindow ? 200.0 : 400.0);
    h.fake.frames.Emit(raw);
    const std::int32_t d_hat = replay.DHat(raw);
    if (test.Step(d_hat, replay.Calibrated(1)) && test.tripped() && trip_tick == 0) trip_tick = n;
  }
  const wire::WatchInfoResponse page = WatchPage(h);
  EXPECT_EQ(page.state, wire::WatchState::kWatching);
  EXPECT_EQ(page.window_samples, kWindow);
  EXPECT_EQ(page.windows, 60u);
  EXPECT_EQ(page.statistic, test.statistic());
  EXPECT_EQ(page.last_z, test.last_z());
  EXPECT_EQ(page.threshold, record.watch.h);
  ASSERT_TRUE(test.tripped());
  EXPECT_EQ(page.stale, 1);
  EXPECT_EQ(page.trip_tick, trip_tick);
  EXPECT_EQ(page.trip_statistic, test.trip_statistic());
  EXPECT_EQ(page.clamps, 0u);
}

// Siegmund's approximation of the CUSUM's average run length for N(mean, 1) increments.
double SiegmundArl(double mean, double k, double h) {
  const double d = mean - k;
  const double b = h + 1.166;
  return (std::exp(-2.0 * d * b) + 2.0 * d * b - 1.0) / (2.0 * d * d);
}

TEST(CoreWatch, APowerStepTripsWithinThePredictedWindows) {
  double spread = 0.0;
  const wire::CalibrationRecord record = RecordWithWatch(/*with_reference=*/false, &spread);
  CoreHarness h;
  Install(h, record);
  Start(h);
  Noise noise(0xBADC0DEu);
  constexpr std::uint32_t kCalm = 100;
  for (std::uint32_t n = 0; n < kCalm * kWindow; ++n) h.fake.frames.Emit(Frame(noise, 200.0));
  EXPECT_EQ(WatchPage(h).stale, 0);
  // The residual's power up by 69 % (the noise amplitude by 30 %): the mean z jumps by 0.69 over
  // the window mean's relative spread measured on the calibration day (about sqrt(2/64) = 0.18 for
  // white noise, more for the observer's coloured output), and the expected windows to the alarm
  // are Siegmund's run length at that drift.
  const double shift = 0.69 / spread;
  const double predicted = SiegmundArl(shift, kK, kH);
  std::uint32_t windows_to_trip = 0;
  for (std::uint32_t w = 1; w <= 40 && windows_to_trip == 0; ++w) {
    for (std::uint32_t n = 0; n < kWindow; ++n) h.fake.frames.Emit(Frame(noise, 260.0));
    if (WatchPage(h).stale == 1) windows_to_trip = w;
  }
  const wire::WatchInfoResponse page = WatchPage(h);
  std::printf("z shift %ld/100: predicted %ld/100 windows to the alarm, tripped after %u\n",
              std::lround(100 * shift), std::lround(100 * predicted),
              static_cast<unsigned>(windows_to_trip));
  ASSERT_GT(shift, 2.0);  // a step the test is built to see quickly
  // One run's delay scatters around the mean: within half and twice the prediction (plus one).
  EXPECT_GE(windows_to_trip, static_cast<std::uint32_t>(std::floor(predicted / 2)));
  EXPECT_LE(windows_to_trip, static_cast<std::uint32_t>(std::ceil(2 * predicted)) + 1);
  EXPECT_EQ(page.trip_tick, (kCalm + windows_to_trip) * kWindow - 1);
  EXPECT_GT(page.trip_statistic, page.threshold);
}

TEST(CoreWatch, InControlItStaysQuietOverALongRun) {
  const wire::CalibrationRecord record = RecordWithWatch(/*with_reference=*/false);
  CoreHarness h;
  Install(h, record);
  Start(h);
  Noise noise(0x5EEDu);
  constexpr std::uint32_t kWindows = 600;  // 38 400 frames, 7.7 s at 5 kHz
  std::int32_t peak = 0;
  for (std::uint32_t w = 0; w < kWindows; ++w) {
    for (std::uint32_t n = 0; n < kWindow; ++n) h.fake.frames.Emit(Frame(noise, 200.0));
    peak = std::max(peak, WatchPage(h).statistic);
  }
  const wire::WatchInfoResponse page = WatchPage(h);
  std::printf("in control over %u windows: the statistic peaked at %ld/100 (h = %ld/100)\n",
              static_cast<unsigned>(kWindows), std::lround(peak * 100.0 / 65536),
              std::lround(record.watch.h * 100.0 / 65536));
  EXPECT_EQ(page.windows, kWindows);
  EXPECT_EQ(page.stale, 0);
  EXPECT_EQ(page.trip_tick, 0u);
  EXPECT_LT(peak, record.watch.h);
  EXPECT_GT(peak, 0);  // the statistic moved: the test ran
}

TEST(CoreWatch, AStartFromRestClearsTheFlagAndAnUncalibratedTestSaysNone) {
  CoreHarness h;
  EXPECT_EQ(WatchPage(h).state, wire::WatchState::kNone);
  Install(h, RecordWithDob());
  EXPECT_EQ(WatchPage(h).state, wire::WatchState::kNone);  // an observer without a test
  const wire::CalibrationRecord record = RecordWithWatch(/*with_reference=*/false);
  Install(h, record);
  EXPECT_EQ(WatchPage(h).state, wire::WatchState::kIdle);
  Start(h);
  Noise noise(0x77u);
  for (std::uint32_t n = 0; n < 10 * kWindow; ++n) h.fake.frames.Emit(Frame(noise, 2000.0));
  EXPECT_EQ(WatchPage(h).stale, 1);  // ten times the amplitude: stale at once
  ASSERT_EQ(h.Request(Command::kAcqStop).status(), Status::kOk);
  EXPECT_EQ(WatchPage(h).state, wire::WatchState::kIdle);
  EXPECT_EQ(WatchPage(h).stale, 1);  // the last run's verdict stays readable
  Start(h);
  const wire::WatchInfoResponse fresh = WatchPage(h);
  EXPECT_EQ(fresh.state, wire::WatchState::kWatching);
  EXPECT_EQ(fresh.stale, 0);
  EXPECT_EQ(fresh.windows, 0u);
}

// The log's model column (kAcqFlagLogWatch): each record carries the test's g and flag as they
// stand at the record's own frame, equal to the host's replay of the test on every frame.
TEST(CoreWatch, TheLogCarriesTheTestsStateAtEachRecord) {
  const wire::CalibrationRecord record = RecordWithWatch(/*with_reference=*/true);
  CoreHarness h;
  Install(h, record);
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;  // 5 kHz, the filter's rate
  c.channel_mask = 1;
  c.decimation = kWindow;  // a record per window: they fit the test log
  c.flags = wire::kAcqFlagLogDob | wire::kAcqFlagLogWatch;
  ASSERT_EQ(h.StartAcquisition(c), Status::kOk);
  Replay replay(record);
  fixed::ResidualCusum test;
  ASSERT_EQ(test.Init(record.watch), Status::kOk);
  Noise noise(0x1234567u);
  std::vector<std::uint32_t> word;  // the replayed test's state after each frame
  for (std::uint32_t n = 0; n < 60 * kWindow; ++n) {
    const auto raw = Frame(noise, n < 30 * kWindow ? 200.0 : 400.0);  // power x4 after 30
    h.fake.frames.Emit(raw);
    const std::int32_t d_hat = replay.DHat(raw);  // before the reference it scales
    (void)test.Step(d_hat, replay.Calibrated(1));
    word.push_back(static_cast<std::uint32_t>(test.statistic()) |
                   (test.tripped() ? 0x80000000u : 0u));
  }
  ASSERT_TRUE(test.tripped());
  const std::uint32_t delay = fixed::DecimatorDelayTicks(kWindow);
  const std::uint32_t lag = (delay + kWindow - 1) / kWindow;
  EXPECT_EQ(lag, Sampler::kMaxWatchLag);  // 973 ticks at D = 64: the longest lag there is
  const testing::PulledLog log = testing::PullLog(h, 0, 0);
  ASSERT_EQ(log.status, Status::kOk);
  // The decimator's settling drops the first records (twice its delay at 64: 31 windows), so
  // the records cover the step's windows and the trip.
  ASSERT_GE(log.count, 25u);
  EXPECT_EQ(log.trailer.record_bytes, 2 + 4 + 4);  // force 1, d_hat, the test's word
  std::size_t stale = 0;
  std::size_t moving = 0;
  for (std::size_t k = 0; k < log.count; ++k) {
    const wire::LogRecord& rec = log.records[k];
    // The state at the record's time as the host writes it (its tick less the decimator's
    // delay): the word of the output `lag` records back, zero before the acquisition.
    ASSERT_LT(rec.sample_index, word.size());
    const std::uint32_t back = lag * kWindow;
    const std::uint32_t expected = rec.sample_index >= back ? word[rec.sample_index - back] : 0u;
    EXPECT_EQ(rec.watch, expected) << "tick " << rec.sample_index;
    stale += (rec.watch >> 31) != 0;
    moving += (rec.watch & 0x7FFFFFFFu) != 0;
  }
  EXPECT_GT(stale, 0u);  // the step's windows are in the log, flagged
  EXPECT_GT(moving, stale);
  // The first record logged stale is the first whose time (tick less the delay) is at or after
  // the tripping window's end, to within a record.
  const wire::WatchInfoResponse page = WatchPage(h);
  for (std::size_t k = 0; k < log.count; ++k) {
    if ((log.records[k].watch >> 31) == 0) continue;
    EXPECT_GE(log.records[k].sample_index - delay, page.trip_tick);
    EXPECT_LT(log.records[k].sample_index - delay, page.trip_tick + kWindow);
    break;
  }
}

// Every supported log rate keeps the residual test's word within the sampler's lag.
TEST(CoreWatch, EveryDecimationsDelayFitsTheWordsLag) {
  std::uint32_t longest = 0;
  for (std::uint32_t d = 2; d <= fixed::kDecimatorMaxFactor; ++d) {
    if (!fixed::IsSupportedDecimation(d)) continue;
    const std::uint32_t delay = fixed::DecimatorDelayTicks(d);
    longest = std::max(longest, (delay + d - 1) / d);
  }
  EXPECT_EQ(longest, Sampler::kMaxWatchLag);
}

TEST(CoreWatch, TheModelColumnNeedsDhatAndATest) {
  CoreHarness h;
  Install(h, RecordWithDob());  // an observer, no test
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;
  c.channel_mask = 1;
  c.flags = wire::kAcqFlagLogDob | wire::kAcqFlagLogWatch;
  testing::Response r = h.Request(Command::kAcqConfigure, c);
  EXPECT_EQ(r.status(), Status::kFailedPrecondition);
  wire::Refusal why;
  ASSERT_EQ(wire::Decode(r.payload(), why), Status::kOk);
  EXPECT_EQ(why.reason, wire::Reason::kNoModelTest);
  c.flags = wire::kAcqFlagLogWatch;  // the word without d_hat: not a layout
  r = h.Request(Command::kAcqConfigure, c);
  EXPECT_EQ(r.status(), Status::kInvalidArgument);
  ASSERT_EQ(wire::Decode(r.payload(), why), Status::kOk);
  EXPECT_EQ(why.reason, wire::Reason::kChannelSelection);
}

}  // namespace
}  // namespace vibid::fw
