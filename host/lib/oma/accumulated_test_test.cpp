// The accumulated (windowed Hotelling) test against its exact law on Gaussian observations drawn
// independently of it, and against the two-sample T² written out.
#include "vibid/oma/accumulated_test.hpp"

#include <gtest/gtest.h>

#include <random>

#include <Eigen/LU>

#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"

namespace vibid::oma {
namespace {

Eigen::MatrixXd Gaussian(int rows, int cols, std::mt19937_64& rng, const Eigen::MatrixXd& mix) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd z(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) z(i, j) = normal(rng);
  return mix * z;
}

TEST(AccumulatedTest, FalseAlarmRateOverReferencesIsTheCalibratedMean) {
  // Correlated observations (a fixed mixing matrix), a fresh reference for each of 400 runs of
  // 10 windows at 5 % asked: each reference keeps its own probability at most 5 % (97.5 %), so
  // over references the windows alarm at the calibration's mean, 4000 × 1.14 % = 46 expected
  // (the references' spread widens Poisson's 99.9 % band, 27 … 68, to about 24 … 72).
  std::mt19937_64 rng(5);
  const int p = 4;
  const Eigen::MatrixXd mix = Eigen::MatrixXd::Identity(p, p) + 0.5 * Eigen::MatrixXd::Ones(p, p);
  int alarms = 0;
  int windows = 0;
  for (int run = 0; run < 400; ++run) {
    AccumulatedTest test(Gaussian(p, 30, rng, mix), 6, 0.05);
    const Eigen::MatrixXd later = Gaussian(p, 60, rng, mix);
    for (int j = 0; j < 60; ++j) {
      const AccumulatedTestResult r = test.Add(later.col(j));
      EXPECT_EQ(r.count, j % 6 + 1);
      EXPECT_EQ(r.complete, r.count == 6);
      if (r.complete) ++windows;
      alarms += r.alarm;
    }
  }
  EXPECT_EQ(windows, 4000);
  EXPECT_NEAR(CalibrateWindow(p, 30, 6, 0.05).mean, 0.0114, 0.0005);
  EXPECT_GE(alarms, 24);
  EXPECT_LE(alarms, 72);
}

TEST(AccumulatedTest, IsTheTwoSampleHotellingStatistic) {
  std::mt19937_64 rng(6);
  const Eigen::MatrixXd reference = Gaussian(3, 20, rng, Eigen::MatrixXd::Identity(3, 3));
  const Eigen::MatrixXd later = Gaussian(3, 4, rng, Eigen::MatrixXd::Identity(3, 3));
  AccumulatedTest test(reference, 4, 0.01);
  AccumulatedTestResult r;
  for (int j = 0; j < 4; ++j) r = test.Add(later.col(j));
  const Eigen::VectorXd mean = reference.rowwise().mean();
  const Eigen::MatrixXd c = reference.colwise() - mean;
  const Eigen::MatrixXd s = c * c.transpose() / 19.0;
  const Eigen::VectorXd d = later.rowwise().mean() - mean;
  const double t2 = d.dot(s.inverse() * d) / (1.0 / 4.0 + 1.0 / 20.0);
  EXPECT_NEAR(r.statistic, t2, 1e-10 * t2);
  EXPECT_NEAR(test.Statistic(later), t2, 1e-10 * t2);
  // Above (m − 1) p / (m − p) F(p, m − p) at 99 %, the average over references, which the
  // calibration also gives.
  const double f = 19.0 * 3.0 / 17.0 * numerics::FQuantile(0.99, 3.0, 17.0);
  EXPECT_NEAR(test.calibration().f_threshold, f, 1e-12);
  EXPECT_EQ(r.threshold, test.calibration().threshold);
  EXPECT_GT(r.threshold, 1.2 * f);
  EXPECT_EQ(r.alarm, t2 > r.threshold);
}

TEST(AccumulatedTest, AShiftGrowsWithTheWindow) {
  // A shift of 0.5 standard deviations in each of 2 components: one observation hardly shows it
  // (noncentrality 0.5: 3 % flagged), 40 do (40 · 0.5 / (1 + 40/200) = 16.7: about 85 % at the
  // calibrated threshold, 73 of these 100 runs).
  std::mt19937_64 rng(7);
  const int p = 2;
  const Eigen::MatrixXd id = Eigen::MatrixXd::Identity(p, p);
  int flagged_one = 0;
  int flagged_forty = 0;
  for (int run = 0; run < 100; ++run) {
    const Eigen::MatrixXd reference = Gaussian(p, 200, rng, id);
    AccumulatedTest one(reference, 1, 0.01);
    AccumulatedTest forty(reference, 40, 0.01);
    const Eigen::MatrixXd later = (Gaussian(p, 40, rng, id).array() + 0.5).matrix();
    flagged_one += one.Add(later.col(0)).alarm;
    AccumulatedTestResult r;
    for (int j = 0; j < 40; ++j) r = forty.Add(later.col(j));
    flagged_forty += r.alarm;
  }
  EXPECT_LE(flagged_one, 12);
  EXPECT_GE(flagged_forty, 60);
}

TEST(AccumulatedTest, RefusesWhatCannotBeTested) {
  const Eigen::MatrixXd reference = Eigen::MatrixXd::Random(4, 5);
  EXPECT_THROW(AccumulatedTest(reference, 3, 0.01), InputError);  // m < p + 2
  const Eigen::MatrixXd ok = Eigen::MatrixXd::Random(2, 30);
  EXPECT_THROW(AccumulatedTest(ok, 0, 0.01), InputError);
  EXPECT_THROW(AccumulatedTest(ok, 3, 0.5), InputError);
  AccumulatedTest test(ok, 3, 0.01);
  EXPECT_THROW(test.Add(Eigen::VectorXd::Zero(3)), InputError);
}

}  // namespace
}  // namespace vibid::oma
