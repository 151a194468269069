#include "vibid/dob/q_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "test_support.hpp"
#include "vibid/common/error.hpp"
#include "vibid/numerics/polynomial.hpp"

namespace vibid::dob {
namespace {

TEST(QFilter, ButterworthMatchesScipyForEveryOrder) {
  for (int n = 1; n <= 8; ++n) {
    const auto ref =
        test::Golden()["butterworth"][std::to_string(n)];  // scipy.signal.butter(n, 1, analog=True)
    const Eigen::VectorXd a = ButterworthCoefficients(n);
    ASSERT_EQ(a.size(), static_cast<Eigen::Index>(ref.size()));
    for (Eigen::Index k = 0; k < a.size(); ++k)
      EXPECT_NEAR(a[k], ref[static_cast<std::size_t>(k)].get<double>(), 1e-12);
  }
}

// methods Eq. 14 with the published N = 5 coefficients 3.236068, 5.236068, 5.236068, 3.236068, 1.
TEST(QFilter, N5R4IsEquation14) {
  const double tau = 0.002;
  const QFilter q = MakeQFilter(5, 4, tau);
  const double a[6] = {
      1.0, 1.0 + std::sqrt(5.0), 3.0 + std::sqrt(5.0), 3.0 + std::sqrt(5.0), 1.0 + std::sqrt(5.0),
      1.0};
  EXPECT_NEAR(a[1], 3.236068, 1e-6);
  EXPECT_NEAR(a[2], 5.236068, 1e-6);
  ASSERT_EQ(q.den.size(), 6);
  ASSERT_EQ(q.num.size(), 2);
  for (int k = 0; k <= 5; ++k) EXPECT_NEAR(q.den[5 - k] / std::pow(tau, k), a[k], 1e-12);
  EXPECT_NEAR(q.num[1], 1.0, 1e-12);
  EXPECT_NEAR(q.num[0] / tau, a[1], 1e-12);
  // Against the scipy-built polynomials too.
  const auto& ref = test::Golden()["q_n5_r4"];
  for (int k = 0; k <= 5; ++k)
    EXPECT_NEAR(q.den[k], ref["den"][static_cast<std::size_t>(k)].get<double>(),
                1e-12 * std::abs(q.den[k]) + 1e-300);
}

TEST(QFilter, AllPoleCaseIsUnityAtDcAndMinus3dBAtTheCutoff) {
  for (int n = 1; n <= 8; ++n) {
    const QFilter q = MakeQFilter(n, n, 0.002);
    const auto h = [&](double w) {
      return numerics::EvaluatePolynomial(q.num, {0.0, w}) /
             numerics::EvaluatePolynomial(q.den, {0.0, w});
    };
    EXPECT_NEAR(std::abs(h(0.0)), 1.0, 1e-15);
    EXPECT_NEAR(20.0 * std::log10(std::abs(h(1.0 / 0.002))), -10.0 * std::log10(2.0), 1e-9);
  }
}

TEST(QFilter, BinomialIsPascalsRow) {
  const Eigen::VectorXd a = BinomialCoefficients(5);
  const double ref[6] = {1, 5, 10, 10, 5, 1};
  for (int k = 0; k <= 5; ++k) EXPECT_EQ(a[k], ref[k]);
}

TEST(QFilter, RealizabilityRangeIsEnforced) {
  EXPECT_THROW(MakeQFilter(0, 0, 0.002), InputError);
  EXPECT_THROW(MakeQFilter(3, 4, 0.002), InputError);
  EXPECT_THROW(MakeQFilter(3, -1, 0.002), InputError);
  EXPECT_THROW(MakeQFilter(3, 2, 0.0), InputError);
  EXPECT_NO_THROW(MakeQFilter(3, 0, 0.002));
}

}  // namespace
}  // namespace vibid::dob
