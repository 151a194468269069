// The saddlepoint tail against closed forms: the chi-square (equal weights), the noncentral
// chi-square (its Poisson mixture of central ones, Johnson, Kotz & Balakrishnan 29.2) and the
// sum of two weighted chi-squares of 2 degrees of freedom (a hypoexponential law:
// P(Q > h) = (a e^{−h/2a} − b e^{−h/2b}) / (a − b)).
#include "vibid/numerics/quadratic_form.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "vibid/numerics/distributions.hpp"

namespace vibid::numerics {
namespace {

TEST(QuadraticFormTail, EqualWeightsAreAChiSquare) {
  const int p = 12;
  for (double tail : {1e-2, 1e-4, 1e-6, 1e-9}) {
    const double h = ChiSquareQuantile(1.0 - tail, p);
    const double got = QuadraticFormTail(Eigen::VectorXd::Ones(p), Eigen::VectorXd::Zero(p), h);
    EXPECT_NEAR(got / tail, 1.0, 0.03) << tail;
  }
}

TEST(QuadraticFormTail, NoncentralChiSquareAsItsPoissonMixture) {
  const int p = 6;
  const double lambda = 4.0;  // Σ δᵢ²
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(p);
  delta(0) = std::sqrt(lambda);
  for (double h : {15.0, 30.0, 50.0}) {
    double exact = 0.0;
    double pois = std::exp(-lambda / 2.0);
    for (int j = 0; j < 200; ++j) {
      exact += pois * (1.0 - ChiSquareCdf(h, p + 2.0 * j));
      pois *= lambda / 2.0 / (j + 1.0);
    }
    const double got = QuadraticFormTail(3.0 * Eigen::VectorXd::Ones(p), delta, 3.0 * h);
    EXPECT_NEAR(got / exact, 1.0, 0.05) << h << " " << exact;
  }
}

TEST(QuadraticFormTail, TwoWeightedChiSquaresOfTwoDegrees) {
  const double a = 2.0;
  const double b = 0.5;
  Eigen::VectorXd w(4);
  w << a, a, b, b;
  for (double h : {10.0, 40.0, 80.0}) {
    const double exact = (a * std::exp(-h / (2 * a)) - b * std::exp(-h / (2 * b))) / (a - b);
    EXPECT_NEAR(QuadraticFormTail(w, Eigen::VectorXd::Zero(4), h) / exact, 1.0, 0.05) << h;
  }
}

TEST(QuadraticFormTail, BelowTheMeanIsTheLargeSide) {
  const double got = QuadraticFormTail(Eigen::VectorXd::Ones(12), Eigen::VectorXd::Zero(12), 6.0);
  EXPECT_NEAR(got, 1.0 - ChiSquareCdf(6.0, 12), 0.02);
}

}  // namespace
}  // namespace vibid::numerics
