// The window threshold for one reference, against references drawn independently of the
// calibration (Gaussian observations through a fixed mixing matrix, each reference's own
// false-alarm probability counted over 20 000 windows of its own), and its limits.
#include "vibid/oma/window_calibration.hpp"

#include <gtest/gtest.h>

#include <random>

#include <Eigen/Cholesky>

#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"

namespace vibid::oma {
namespace {

struct Tally {
  int below_asked = 0;  // references whose own probability is at most the asked one
  int in_band = 0;      // ... within the stated band
  double mean = 0.0;    // their mean probability
};

// `refs` references of m observations of p residuals; each one's probability of T² > h over
// windows of k, counted.
Tally Count(int p, int m, int k, double h, double asked, const WindowCalibration& c, int refs) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd mix = Eigen::MatrixXd::Identity(p, p) + 0.7 * Eigen::MatrixXd::Ones(p, p);
  mix(0, p - 1) = 2.0;
  const int windows = 20000;
  // Monte Carlo error of one reference's count: binomial, about 3 % of the asked 5 %.
  const double slack = 3.0 * std::sqrt(asked * (1.0 - asked) / windows);
  Tally t;
  for (int r = 0; r < refs; ++r) {
    Eigen::MatrixXd ref(p, m);
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < p; ++i) ref(i, j) = normal(rng);
    ref = mix * ref;
    const Eigen::VectorXd mean = ref.rowwise().mean();
    const Eigen::MatrixXd centred = ref.colwise() - mean;
    const Eigen::MatrixXd s = centred * centred.transpose() / (m - 1.0);
    const Eigen::LLT<Eigen::MatrixXd> llt(s);
    int over = 0;
    for (int w = 0; w < windows; ++w) {
      Eigen::VectorXd z(p);
      for (int i = 0; i < p; ++i) z(i) = normal(rng);
      // The mean of k unchanged observations: N(0, Σ/k).
      const Eigen::VectorXd d = mix * z / std::sqrt(static_cast<double>(k)) - mean;
      const double t2 = d.dot(llt.solve(d)) / (1.0 / k + 1.0 / m);
      over += t2 > h;
    }
    const double prob = static_cast<double>(over) / windows;
    t.below_asked += prob <= asked + slack;
    t.in_band += prob >= c.low - slack && prob <= c.high + slack;
    t.mean += prob / refs;
  }
  return t;
}

TEST(WindowCalibration, TheReferenceTheUserHasKeepsTheRateAsked) {
  // p = 4, m = 30, windows of 6 at 5 %: 300 references. At the calibrated threshold 97.5 % of
  // references give at most 5 % and 95 % lie within the band (binomial: 99.9 % of runs at least
  // 92 % and 90 %); at Hotelling's F quantile only about half give at most 5 %, their mean
  // being the 5 % asked.
  const int p = 4;
  const int m = 30;
  const int k = 6;
  const double asked = 0.05;
  const WindowCalibration c = CalibrateWindow(p, m, k, asked);
  std::printf("threshold %.2f (F %.2f); band %.4f … %.4f, mean %.4f; at F %.4f … %.4f\n",
              c.threshold, c.f_threshold, c.low, c.high, c.mean, c.f_low, c.f_high);
  EXPECT_GT(c.threshold, 1.2 * c.f_threshold);
  EXPECT_NEAR(c.high, asked, 0.002);
  EXPECT_LT(c.low, 0.5 * asked);
  const int refs = 300;
  const Tally at = Count(p, m, k, c.threshold, asked, c, refs);
  std::printf("calibrated: %d of %d at most 5 %%, %d within the band, mean %.4f\n", at.below_asked,
              refs, at.in_band, at.mean);
  EXPECT_GE(at.below_asked, 276);
  EXPECT_GE(at.in_band, 270);
  // The mean rests on the few references with the highest probabilities: 300 give it to ±15 %.
  EXPECT_NEAR(at.mean / c.mean, 1.0, 0.25);
  const Tally f = Count(p, m, k, c.f_threshold, asked, c, refs);
  std::printf("F quantile: %d of %d at most 5 %%, mean %.4f\n", f.below_asked, refs, f.mean);
  EXPECT_LT(f.below_asked, 240);
  EXPECT_NEAR(f.mean / asked, 1.0, 0.1);
}

TEST(WindowCalibration, TheDefaultRateOverFortyThousandHoursTwoSided) {
  // The watch's default sizes (2 channels, 2 modes: p = 8 residuals; a 30-minute reference: m = 144
  // blocks of 10 s; windows of 60 blocks at 0.01 false alarms per hour: 1/600 per window), each
  // reference drawn afresh and watched 100 h with window means drawn from the residuals' law:
  // 400 references, 40 000 h. The count is expected at the references' mean rate, its spread
  // Poisson's and the references' (var = Σ λ + Σ (λᵣ − λ)², both from the calibration's draws
  // as mean and band); 3.3 standard deviations each side.
  const int p = 8;
  const int m = 144;
  const int k = 60;
  const double per_window = 0.01 * 600.0 / 3600.0;
  const WindowCalibration c = CalibrateWindow(p, m, k, per_window);
  const int refs = 400;
  const int windows = 600;  // 100 h each
  std::mt19937_64 rng(12);
  std::normal_distribution<double> normal;
  int alarms = 0;
  for (int r = 0; r < refs; ++r) {
    Eigen::MatrixXd ref(p, m);
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < p; ++i) ref(i, j) = normal(rng);
    const Eigen::VectorXd mean = ref.rowwise().mean();
    const Eigen::MatrixXd centred = ref.colwise() - mean;
    const Eigen::LLT<Eigen::MatrixXd> llt(centred * centred.transpose() / (m - 1.0));
    for (int w = 0; w < windows; ++w) {
      Eigen::VectorXd d(p);
      for (int i = 0; i < p; ++i) d(i) = normal(rng) / std::sqrt(static_cast<double>(k));
      d -= mean;
      alarms += d.dot(llt.solve(d)) / (1.0 / k + 1.0 / m) > c.threshold;
    }
  }
  const double expected = c.mean * refs * windows;
  const double spread = (c.high - c.low) / 4.0 * windows;
  const double sd = std::sqrt(expected + refs * spread * spread);
  std::printf(
      "40 000 h at 0.01/h asked (400 alarms): %d, %.1f expected (%.1f … %.1f); threshold %.2f (F "
      "%.2f), band %.2g … %.2g per hour, mean %.2g; at the F quantile %.2g … %.2g\n",
      alarms, expected, expected - 3.3 * sd, expected + 3.3 * sd, c.threshold, c.f_threshold,
      6.0 * c.low, 6.0 * c.high, 6.0 * c.mean, 6.0 * c.f_low, 6.0 * c.f_high);
  EXPECT_GE(alarms, expected - 3.3 * sd);
  EXPECT_LE(alarms, expected + 3.3 * sd);
  EXPECT_GT(expected - 3.3 * sd, 0.0);    // the lower bound can fail
  EXPECT_LT(expected + 3.3 * sd, 400.0);  // and the upper one lies below the rate asked
}

TEST(WindowCalibration, ALongReferenceIsTheChiSquare) {
  // With m → ∞ the reference is the truth: T² → χ²(p), the band closes on the asked rate.
  const WindowCalibration c = CalibrateWindow(12, 1000000, 60, 1e-3);
  EXPECT_NEAR(c.threshold / numerics::ChiSquareQuantile(1.0 - 1e-3, 12), 1.0, 0.01);
  EXPECT_NEAR(c.low / 1e-3, 1.0, 0.05);
}

TEST(WindowCalibration, AdvisesAReferenceThatNarrowsTheBand) {
  // At the watch's default sizes the band's low end lies far below the rate asked (the window's
  // 60 blocks against the reference's 144: its mean's error weighs); a longer reference narrows
  // it, and a long enough one is advised as it is.
  const double asked = 1.0 / 600.0;
  const WindowCalibration now = CalibrateWindow(12, 144, 60, asked);
  EXPECT_LT(now.low, asked / 5.0);
  const ReferenceAdvice advice = AdviseReference(12, 144, 60, asked);
  EXPECT_GT(advice.observations, 144);
  EXPECT_GE(advice.calibration.low, asked / 5.0);
  EXPECT_LT(CalibrateWindow(12, advice.observations * 2 / 3, 60, asked).low, asked / 5.0);
  EXPECT_EQ(AdviseReference(12, 5000, 60, asked).observations, 5000);
}

TEST(WindowCalibration, RefusesWhatItCannotCalibrate) {
  EXPECT_THROW(CalibrateWindow(12, 13, 6, 0.01), InputError);
  EXPECT_THROW(CalibrateWindow(12, 100, 0, 0.01), InputError);
  EXPECT_THROW(CalibrateWindow(12, 100, 6, 0.5), InputError);
}

}  // namespace
}  // namespace vibid::oma
