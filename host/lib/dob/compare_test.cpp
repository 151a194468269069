#include "vibid/dob/compare.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "vibid/common/error.hpp"

namespace vibid::dob {
namespace {

TEST(Compare, ClosedFormsOnKnownSignals) {
  const double fs = 1000.0;
  const Eigen::Index n = 4000;
  Eigen::VectorXd m(n), e(n), shifted(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    m[k] = std::sin(2.0 * std::numbers::pi * 3.0 * t);
    e[k] = 0.9 * m[k];
    shifted[k] = std::sin(2.0 * std::numbers::pi * 3.0 * (t - 0.012));
  }
  const Agreement same = CompareSignals(m, m, fs);
  EXPECT_EQ(same.fit_percent, 100.0);
  EXPECT_NEAR(same.correlation, 1.0, 1e-12);
  EXPECT_EQ(same.delay_s, 0.0);
  // A 0.9 gain: fit = 100 (1 - 0.1), correlation 1, rmse 0.1 * rms(sin) = 0.1/sqrt(2).
  const Agreement scaled = CompareSignals(e, m, fs);
  EXPECT_NEAR(scaled.fit_percent, 90.0, 1e-9);
  EXPECT_NEAR(scaled.correlation, 1.0, 1e-12);
  EXPECT_NEAR(scaled.rmse_n, 0.1 / std::sqrt(2.0), 1e-9);
  // 12 samples late.
  EXPECT_NEAR(CompareSignals(shifted, m, fs).delay_s, 0.012, 1e-12);
}

TEST(Compare, RefusesMismatchedInput) {
  EXPECT_THROW(CompareSignals(Eigen::VectorXd::Ones(3), Eigen::VectorXd::Ones(4), 10.0),
               InputError);
  EXPECT_THROW(CompareSignals(Eigen::VectorXd::Ones(1), Eigen::VectorXd::Ones(1), 10.0),
               InputError);
}

}  // namespace
}  // namespace vibid::dob
