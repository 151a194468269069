// Quantiles and distribution values against scipy.stats 1.10.1 (scripts/golden/distributions.py,
// an independent implementation: Cephes), and properties: CDF(quantile(p)) = p, symmetry.
#include "vibid/numerics/distributions.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "vibid/common/error.hpp"

namespace vibid::numerics {
namespace {

void ExpectRel(double actual, double expected, double rel = 1e-9) {
  EXPECT_NEAR(actual, expected, rel * std::max(1.0, std::fabs(expected))) << expected;
}

TEST(Distributions, StudentTQuantilesEqualScipy) {
  // Source: scipy.stats.t.ppf (scripts/golden/distributions.py).
  ExpectRel(StudentTQuantile(0.975, 1), 12.706204736432095);
  ExpectRel(StudentTQuantile(0.975, 5), 2.5705818366147395);
  ExpectRel(StudentTQuantile(0.975, 19), 2.093024054408263);
  ExpectRel(StudentTQuantile(0.975, 100), 1.9839715184496334);
  // mpmath at 40 digits (the same script): scipy's 5.84090929975643 is 1.7e-9 off here.
  ExpectRel(StudentTQuantile(0.995, 3), 5.8409093097333572607);
  ExpectRel(StudentTQuantile(0.05, 7), -1.8945786050613054);
}

TEST(Distributions, ChiSquareQuantilesEqualScipy) {
  // Source: scipy.stats.chi2.ppf (scripts/golden/distributions.py).
  ExpectRel(ChiSquareQuantile(0.95, 1), 3.841458820694124);
  ExpectRel(ChiSquareQuantile(0.95, 10), 18.307038053275146);
  ExpectRel(ChiSquareQuantile(0.99, 10), 23.209251158954356);
  ExpectRel(ChiSquareQuantile(0.999, 64), 104.71632526304057);
  ExpectRel(ChiSquareQuantile(0.9999, 200), 283.0602538242421);
  ExpectRel(ChiSquareQuantile(0.01, 4), 0.2971094805065319);
}

TEST(Distributions, FQuantilesEqualScipy) {
  // Source: scipy.stats.f.ppf (scripts/golden/distributions.py).
  ExpectRel(FQuantile(0.95, 3, 10), 3.7082648190468435);
  ExpectRel(FQuantile(0.999, 64, 400), 1.7234867701262289);
  ExpectRel(FQuantile(0.99, 1, 1), 4052.1806954768217);
  ExpectRel(FQuantile(0.5, 7, 30), 0.9271891104241207);
}

TEST(Distributions, NormalAndCdfValuesEqualScipy) {
  // Source: scipy.stats norm.ppf, chi2.cdf, t.cdf, f.cdf (scripts/golden/distributions.py).
  ExpectRel(NormalQuantile(0.975), 1.959963984540054);
  EXPECT_NEAR(NormalQuantile(0.5), 0.0, 1e-12);
  ExpectRel(NormalQuantile(1e-6), -4.753424308822899);
  ExpectRel(ChiSquareCdf(3.0, 2.5), 0.6941503705541809, 1e-12);
  ExpectRel(StudentTCdf(-2.0, 4), 0.05805826175840775, 1e-12);
  ExpectRel(FCdf(1.7, 5, 12), 0.7909215776493592, 1e-12);
}

TEST(Distributions, QuantileInvertsTheCdf) {
  for (double p : {1e-4, 0.1, 0.5, 0.9, 0.999}) {
    for (double dof : {1.0, 2.5, 17.0, 300.0}) {
      EXPECT_NEAR(ChiSquareCdf(ChiSquareQuantile(p, dof), dof), p, 1e-10);
      EXPECT_NEAR(StudentTCdf(StudentTQuantile(p, dof), dof), p, 1e-10);
      EXPECT_NEAR(FCdf(FQuantile(p, dof, 2.0 * dof), dof, 2.0 * dof), p, 1e-10);
    }
    // Symmetry of the t and normal distributions.
    EXPECT_NEAR(StudentTQuantile(p, 6.0), -StudentTQuantile(1.0 - p, 6.0), 1e-9);
    EXPECT_NEAR(NormalQuantile(p), -NormalQuantile(1.0 - p), 1e-9);
  }
}

TEST(Distributions, RefusesProbabilitiesAndDofOutOfRange) {
  EXPECT_THROW(ChiSquareQuantile(0.0, 3), InputError);
  EXPECT_THROW(ChiSquareQuantile(1.0, 3), InputError);
  EXPECT_THROW(StudentTQuantile(0.5, 0.0), InputError);
  EXPECT_THROW(FQuantile(0.5, 1.0, -2.0), InputError);
  EXPECT_THROW(NormalQuantile(std::nan("")), InputError);
}

}  // namespace
}  // namespace vibid::numerics
