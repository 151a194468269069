// Output covariances against the closed form of an AR(1) process; the decimator's pass band and
// its rejection of what would fold back.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/QR>

#include "vibid/common/error.hpp"
#include "vibid/oma/ssi_cov.hpp"

namespace vibid::oma {
namespace {

TEST(OutputCovariances, EqualTheClosedFormOfAnAr1Process) {
  // y_t = a y_{t−1} + e_t, var e = 1: R_k = a^k / (1 − a²) (a textbook closed form).
  const double a = 0.8;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int n = 400000;
  Eigen::MatrixXd y(n, 1);
  double state = 0.0;
  for (int t = 0; t < n; ++t) y(t, 0) = state = a * state + normal(rng);
  const Eigen::MatrixXd r = OutputCovariances(y, 5);
  for (int k = 0; k <= 5; ++k) {
    const double expected = std::pow(a, k) / (1.0 - a * a);
    // Standard error of the estimate is about 0.02 here (Bartlett); 4 of them.
    EXPECT_NEAR(r(0, k), expected, 0.08) << "lag " << k;
  }
}

TEST(OutputCovariances, CrossCovariancesKeepTheirOrder) {
  // Channel 1 is channel 0 delayed by 2 samples: R_k(1, 0) = E[y1_{t+k} y0_t] peaks at k = 2.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int n = 100000;
  Eigen::MatrixXd y(n, 2);
  for (int t = 0; t < n; ++t) y(t, 0) = normal(rng);
  for (int t = 0; t < n; ++t) y(t, 1) = t >= 2 ? y(t - 2, 0) : 0.0;
  const Eigen::MatrixXd r = OutputCovariances(y, 3);
  EXPECT_NEAR(r(1, 2 * 2 + 0), 1.0, 0.02);  // R_2(1, 0)
  EXPECT_NEAR(r(0, 2 * 2 + 1), 0.0, 0.02);  // R_2(0, 1)
  EXPECT_NEAR(r(1, 1 * 2 + 0), 0.0, 0.02);  // R_1(1, 0)
  EXPECT_THROW(OutputCovariances(y.topRows(3), 3), InputError);
}

double SineAmplitude(const Eigen::VectorXd& x, double f_cycles_per_sample) {
  // Least-squares amplitude of a sine of known frequency.
  Eigen::MatrixXd basis(x.size(), 2);
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    basis(t, 0) = std::cos(2.0 * std::numbers::pi * f_cycles_per_sample * static_cast<double>(t));
    basis(t, 1) = std::sin(2.0 * std::numbers::pi * f_cycles_per_sample * static_cast<double>(t));
  }
  const Eigen::Vector2d c = basis.colPivHouseholderQr().solve(x);
  return c.norm();
}

TEST(Decimate, PassesTheBandAndRejectsWhatWouldFoldOntoIt) {
  const int factor = 8;
  const int n = 40000;
  for (double f_out : {0.05, 0.2, 0.4}) {  // in cycles per output sample: the band kept
    Eigen::MatrixXd y(n, 1);
    for (int t = 0; t < n; ++t) y(t, 0) = std::sin(2.0 * std::numbers::pi * f_out / factor * t);
    const Eigen::MatrixXd d = Decimate(y, factor);
    EXPECT_NEAR(SineAmplitude(d.col(0), f_out), 1.0, 3e-3) << f_out;
  }
  // 0.7 of the output rate folds onto 0.3: attenuated by at least 40 dB.
  Eigen::MatrixXd y(n, 1);
  for (int t = 0; t < n; ++t) y(t, 0) = std::sin(2.0 * std::numbers::pi * 0.7 / factor * t);
  const Eigen::MatrixXd d = Decimate(y, factor);
  EXPECT_LT(SineAmplitude(d.col(0), 0.3), 0.01);
  EXPECT_EQ(Decimate(y, 1).rows(), n);
  EXPECT_THROW(Decimate(y.topRows(100), factor), InputError);
}

}  // namespace
}  // namespace vibid::oma
