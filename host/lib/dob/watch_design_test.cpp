// The residual test's design: Siegmund's run length against published CUSUM run lengths and a
// Monte Carlo of Gaussian increments, and the whole chain (a calibration day replayed, the design,
// the board's fixed-point kernel) over 100 simulated hours in control: the false alarms it raises
// against the rate the design was asked for.
#include "vibid/dob/watch_design.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include "vibid/common/error.hpp"

namespace vibid::dob {
namespace {

TEST(CusumRunLength, MatchesPublishedRunLengths) {
  // Montgomery, Introduction to Statistical Quality Control (Wiley, 6th ed. 2009), section 9.1:
  // the two-sided tabular CUSUM with k = 1/2 has ARL0 = 168 at h = 4 and 465 at h = 5, and at a
  // one-sigma shift ARL1 = 8.38 and 10.4. The two-sided in-control run length is half the
  // one-sided one (1/ARL = 1/ARL+ + 1/ARL-); a shift up is caught by the upper side alone.
  EXPECT_NEAR(CusumRunLength(0.0, 0.5, 4.0) / 2.0, 168.0, 0.02 * 168.0);
  EXPECT_NEAR(CusumRunLength(0.0, 0.5, 5.0) / 2.0, 465.0, 0.02 * 465.0);
  EXPECT_NEAR(CusumRunLength(1.0, 0.5, 4.0), 8.38, 0.02 * 8.38);
  EXPECT_NEAR(CusumRunLength(1.0, 0.5, 5.0), 10.4, 0.02 * 10.4);
}

TEST(CusumRunLength, MatchesAMonteCarloOfGaussianIncrements) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> z(0.0, 1.0);
  for (const double h : {3.0, 5.0}) {
    constexpr int kRuns = 4000;
    double total = 0.0;
    for (int run = 0; run < kRuns; ++run) {
      double g = 0.0;
      int n = 0;
      do {
        g = std::max(0.0, g + z(rng) - 0.5);
        ++n;
      } while (g <= h);
      total += n;
    }
    const double mean = total / kRuns;
    const double predicted = CusumRunLength(0.0, 0.5, h);
    // Run lengths are near-geometric (spread about their mean): 3 standard errors of the mean
    // plus the approximation's own 2 %.
    EXPECT_NEAR(mean, predicted, predicted * (3.0 / std::sqrt(kRuns) + 0.02)) << "h = " << h;
  }
}

TEST(RegularizedGammaLower, MatchesChiSquareTables) {
  // Chi-square upper 5 % points (Abramowitz & Stegun, Table 26.8): P(nu / 2, x / 2) = 0.95 at
  // x = 3.841 (nu 1), 18.307 (nu 10), 124.342 (nu 100); and P(1, x) = 1 - exp(-x) in closed form.
  EXPECT_NEAR(RegularizedGammaLower(0.5, 3.841 / 2), 0.95, 2e-5);
  EXPECT_NEAR(RegularizedGammaLower(5.0, 18.307 / 2), 0.95, 2e-5);
  EXPECT_NEAR(RegularizedGammaLower(50.0, 124.342 / 2), 0.95, 2e-5);
  EXPECT_NEAR(RegularizedGammaLower(1.0, 0.3), 1.0 - std::exp(-0.3), 1e-14);
  EXPECT_NEAR(RegularizedGammaLower(1.0, 7.0), 1.0 - std::exp(-7.0), 1e-14);
}

TEST(CusumRunLengthGamma, TendsToTheGaussianOneAndMatchesAMonteCarloOfGammaIncrements) {
  // A Gamma of large shape is nearly Gaussian: the chain then agrees with Siegmund.
  EXPECT_NEAR(CusumRunLengthGamma(1e6, 1.0, 0.0, 0.5, 4.0), CusumRunLength(0.0, 0.5, 4.0),
              0.02 * CusumRunLength(0.0, 0.5, 4.0));
  // A skewed one (shape 15, skew 0.52): the Monte Carlo of its own increments.
  std::mt19937_64 rng(3);
  const double shape = 15.0;
  std::gamma_distribution<double> e(shape, 1.0 / shape);
  for (const double ratio : {1.0, 1.0 + 1.0 / std::sqrt(shape)}) {
    constexpr int kRuns = 4000;
    double total = 0.0;
    for (int run = 0; run < kRuns; ++run) {
      double g = 0.0;
      int n = 0;
      do {
        g = std::max(0.0, g + (ratio * e(rng) - 1.0) * std::sqrt(shape) - 0.5);
        ++n;
      } while (g <= 4.0);
      total += n;
    }
    const double mean = total / kRuns;
    const double chain = CusumRunLengthGamma(shape, ratio, std::sqrt(shape), 0.5, 4.0);
    EXPECT_NEAR(mean, chain, chain * (3.0 / std::sqrt(kRuns) + 0.02)) << "ratio " << ratio;
  }
  // Skewed increments alarm sooner in control than Gaussian ones at the same h.
  EXPECT_LT(CusumRunLengthGamma(15.0, 1.0, 0.0, 0.5, 4.0), 0.8 * CusumRunLength(0.0, 0.5, 4.0));
}

TEST(CusumRunLengthGammaAffine, MatchesAMonteCarloOfShiftedAndScaledGammaIncrements) {
  // The increments a misestimated centre and spread give: scale z + offset, z the standardized
  // Gamma of shape 15. Their own Monte Carlo, at offsets either side and a wider and a narrower
  // spread.
  std::mt19937_64 rng(5);
  const double shape = 15.0;
  std::gamma_distribution<double> e(shape, 1.0);
  for (const auto& [scale, offset] : {std::pair{1.1, 0.05}, std::pair{0.9, -0.05}}) {
    constexpr int kRuns = 4000;
    double total = 0.0;
    for (int run = 0; run < kRuns; ++run) {
      double g = 0.0;
      int n = 0;
      do {
        g = std::max(0.0, g + scale * (e(rng) - shape) / std::sqrt(shape) + offset - 0.5);
        ++n;
      } while (g <= 4.0);
      total += n;
    }
    const double mean = total / kRuns;
    const double chain = CusumRunLengthGammaAffine(shape, scale, offset, 0.5, 4.0);
    EXPECT_NEAR(mean, chain, chain * (3.0 / std::sqrt(kRuns) + 0.02)) << "scale " << scale;
  }
  // Either error moves the run length: a wider spread or a centre set low alarms sooner.
  EXPECT_LT(CusumRunLengthGammaAffine(shape, 1.1, 0.0, 0.5, 4.0),
            0.8 * CusumRunLengthGammaAffine(shape, 1.0, 0.0, 0.5, 4.0));
  EXPECT_LT(CusumRunLengthGammaAffine(shape, 1.0, 0.05, 0.5, 4.0),
            0.9 * CusumRunLengthGammaAffine(shape, 1.0, 0.0, 0.5, 4.0));
}

TEST(CusumThreshold, InvertsTheRunLength) {
  for (const double arl : {50.0, 3600.0, 1.0e7}) {
    const double h = CusumThreshold(arl, 0.5);
    EXPECT_NEAR(CusumRunLength(0.0, 0.5, h), arl, 1e-6 * arl);
  }
  EXPECT_THROW(CusumThreshold(1.0, 0.5), InputError);
  EXPECT_THROW(CusumThreshold(100.0, -0.1), InputError);
}

// A residual like the observer's in control: near-Gaussian integer noise (four xorshift32
// uniforms) through a one-pole low-pass (pole 0.9: correlation time (1 + 0.9) / (1 - 0.9) = 19
// samples), at about 2^-13 of d_hat's full scale.
class Residual {
 public:
  explicit Residual(std::uint32_t seed) : state_(seed) {}
  std::int32_t Next(double gain = 1.0) {
    double u = 0.0;
    for (int i = 0; i < 4; ++i) {
      state_ ^= state_ << 13;
      state_ ^= state_ >> 17;
      state_ ^= state_ << 5;
      u += static_cast<double>(state_) / 4294967296.0 - 0.5;
    }
    y_ = 0.9 * y_ + u * std::sqrt(3.0) * 262144.0 * std::sqrt(1.0 - 0.81);
    return static_cast<std::int32_t>(std::lround(gain * y_));
  }

 private:
  std::uint32_t state_;
  double y_ = 0.0;
};

TEST(DesignWatch, ChoosesTheWindowFromTheCorrelationTimeAndRefusesAShortRecording) {
  constexpr double kFs = 500.0;
  Residual day(11);
  std::vector<std::int32_t> d_hat(static_cast<std::size_t>(3600 * kFs));
  for (auto& v : d_hat) v = day.Next();
  const WatchDesign d = DesignWatch(d_hat, {}, 0.0, kFs, WatchOptions{});
  // 19 samples of correlation time, 40 of them to a window.
  EXPECT_NEAR(d.correlation_samples, 19.0, 2.0);
  EXPECT_NEAR(d.params.window_samples, 40.0 * 19.0, 80.0);
  EXPECT_LT(d.window_lag1, 0.1);
  EXPECT_EQ(d.params.reference_gain, 0);
  // One false alarm in 1000 hours at the 97.5 % point of what this calibration gives: the band's
  // upper end is the rate asked (to the design's iteration), its lower end below it, and the
  // run length stated at the calibration's own estimates is the chain's at its h and the
  // partial sums' variance ratio.
  EXPECT_NEAR(d.false_alarms_high, 1.0e-3, 0.05e-3);
  EXPECT_LT(d.false_alarms_low, 0.9 * d.false_alarms_high);
  EXPECT_GT(d.false_alarms_low, 0.0);
  EXPECT_NEAR(
      CusumRunLengthGammaAffine(d.gamma_shape, std::sqrt(d.path_variance_ratio), 0.0, d.k, d.h),
      d.arl0_windows, 1e-6 * d.arl0_windows);
  // The centre's standard error: at least that of independent windows, 1 / sqrt(n) spreads.
  EXPECT_GE(d.centre_se_spreads, 1.0 / std::sqrt(static_cast<double>(d.calibration_windows)));
  EXPECT_GT(d.h, d.h_gaussian);  // the skewed window mean needs a higher threshold

  const std::vector<std::int32_t> short_day(d_hat.begin(), d_hat.begin() + 20000);
  try {
    (void)DesignWatch(short_day, {}, 0.0, kFs, WatchOptions{});
    ADD_FAILURE() << "a recording of 26 windows was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("record at least"), std::string::npos) << e.what();
  }
  const std::vector<std::int32_t> zero(400000, 0);
  EXPECT_THROW((void)DesignWatch(zero, {}, 0.0, kFs, WatchOptions{}), InputError);
}

// The hold-off against a first-order observer pole, x[n] = rho x[n-1] + u[n]: its start
// transient is A rho^n, so the samples after which the transient's remaining r^2 is at most
// kHoldoffSpreads window-sum spreads solve A^2 rho^(2n) / (1 - rho^2) = 0.1 S. At rho 0.99,
// A 2^26, S 2^36: n = ln(2^52 / (0.0199 * 0.1 * 2^36)) / (-2 ln 0.99) = 861.164 (numpy, this
// formula), and summing A^2 rho^(2m) for m >= n directly (numpy cumsum, no closed form) first
// falls to 0.1 S at n = 862, the whole samples the kernel holds off.
TEST(WatchHoldoff, MatchesTheClosedFormOfAFirstOrderPole) {
  fixed::FilterDescription d;
  d.input_count = 1;
  d.paths[0].section_count = 1;
  d.paths[0].sections[0].shift = 1;  // Q30
  d.paths[0].sections[0].b0 = 1 << 20;
  d.paths[0].sections[0].a1 = -static_cast<std::int32_t>(std::lround(0.99 * (1 << 30)));
  EXPECT_NEAR(SlowestPoleRadius(d), 0.99, 1e-9);
  // A resonant pair at radius 0.995 in a second section: |z|^2 = a2.
  d.paths[0].section_count = 2;
  d.paths[0].sections[1].shift = 1;
  d.paths[0].sections[1].a1 =
      static_cast<std::int32_t>(std::lround(-2.0 * 0.995 * std::cos(0.3) * (1 << 30)));
  d.paths[0].sections[1].a2 = static_cast<std::int32_t>(std::lround(0.995 * 0.995 * (1 << 30)));
  EXPECT_NEAR(SlowestPoleRadius(d), 0.995, 1e-8);

  const double n = HoldoffSamples(0.99, std::ldexp(1.0, 26), std::ldexp(1.0, 36));
  EXPECT_NEAR(n, 861.164, 0.001);
  EXPECT_EQ(std::ceil(n), 862.0);
  EXPECT_EQ(HoldoffSamples(0.0, 1.0, 1.0), 0.0);  // no feedback: no transient beyond the fill
  EXPECT_THROW((void)HoldoffSamples(1.0, 1.0, 1.0), InputError);
}

TEST(DesignWatch, HoldsOffTheObserversStartInWholeWindowsAndRefusesBeyond255) {
  constexpr double kFs = 500.0;
  Residual day(11);
  std::vector<std::int32_t> d_hat(static_cast<std::size_t>(600 * kFs));
  for (auto& v : d_hat) v = day.Next();
  WatchOptions options;
  const WatchDesign none = DesignWatch(d_hat, {}, 0.0, kFs, options);
  EXPECT_EQ(none.params.holdoff_windows, 1);  // at least the first window
  options.observer_pole_radius = 0.99;
  const WatchDesign d = DesignWatch(d_hat, {}, 0.0, kFs, options);
  const double w = d.params.window_samples;
  // The largest residual the kernel forms: d_hat at full scale times the Q32 gain.
  const double a = std::ldexp(static_cast<double>(d.params.residual_gain), -1);
  EXPECT_DOUBLE_EQ(d.holdoff_samples, HoldoffSamples(0.99, a, w * d.sigma0));
  EXPECT_EQ(d.params.holdoff_windows, static_cast<int>(std::ceil(d.holdoff_samples / w)));
  EXPECT_GT(d.params.holdoff_windows, 1);
  // A pole this slow (time constant 200 000 samples) would need far more than 255 windows.
  options.observer_pole_radius = 1.0 - 5e-6;
  try {
    (void)DesignWatch(d_hat, {}, 0.0, kFs, options);
    ADD_FAILURE() << "a hold-off beyond 255 windows was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more than the 255"), std::string::npos) << e.what();
  }
}

// The acceptance run: one hour of calibration day, the test designed for one false alarm per
// hour, then 100 hours in control through the board's kernel (restarted after each alarm, as the
// user would after checking the rig): the alarms counted against the 100 stated.
TEST(DesignWatch, FalseAlarmRateOverAHundredHoursMatchesTheStatedOne) {
  constexpr double kFs = 500.0;
  Residual day(0xCA11B0u);
  std::vector<std::int32_t> calibration(static_cast<std::size_t>(3600 * kFs));
  for (auto& v : calibration) v = day.Next();
  WatchOptions options;
  options.false_alarms_per_hour = 1.0;
  const WatchDesign d = DesignWatch(calibration, {}, 0.0, kFs, options);

  fixed::ResidualCusum kernel;
  ASSERT_EQ(kernel.Init(d.params), Status::kOk);
  Residual run(0x5EED5u);
  constexpr double kHours = 100.0;
  const auto samples = static_cast<std::uint64_t>(kHours * 3600 * kFs);
  int alarms = 0;
  for (std::uint64_t n = 0; n < samples; ++n) {
    if (kernel.Step(run.Next(), 0) && kernel.tripped()) {
      ++alarms;
      kernel.Reset();
    }
  }
  const double low = d.false_alarms_low * kHours;
  const double high = d.false_alarms_high * kHours;
  std::printf(
      "W %u (%.2f s), skew of the window mean %.3f (two-moment Gamma %.3f), k %.2f, "
      "h %.3f (Siegmund %.3f): %d false alarms in %.0f h, this calibration's band %.1f to %.1f "
      "(asked %.0f); %.1f windows to detect a shift of %.2g spreads\n",
      d.params.window_samples, d.window_s, d.window_skew, 2.0 * d.sigma0 / d.mu0, d.k, d.h,
      d.h_gaussian, alarms, kHours, low, high, options.false_alarms_per_hour * kHours,
      d.detection_windows, 2.0 * d.k);
  // Alarm counts of a renewal process with near-geometric run lengths scatter like Poisson
  // counts: the band's ends widened by 2 sqrt of themselves (their 95 % scatter), both sides.
  EXPECT_GE(alarms, low - 2.0 * std::sqrt(low));
  EXPECT_LE(alarms, high + 2.0 * std::sqrt(high));
}

}  // namespace
}  // namespace vibid::dob
