#include "vibid/numerics/polynomial.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "vibid/common/error.hpp"

namespace vibid::numerics {
namespace {

TEST(Polynomial, EvaluateAndMultiply) {
  const Eigen::Vector3d a(1.0, -3.0, 2.0);  // (x - 1)(x - 2)
  const Eigen::Vector2d b(2.0, 1.0);        // 2x + 1
  EXPECT_EQ(EvaluatePolynomial(a, Complex(2.0, 0.0)), Complex(0.0, 0.0));
  EXPECT_EQ(EvaluatePolynomial(a, Complex(0.0, 1.0)), Complex(1.0, -3.0));
  const Eigen::VectorXd c = MultiplyPolynomials(a, b);
  ASSERT_EQ(c.size(), 4);
  EXPECT_EQ(c, Eigen::Vector4d(2.0, -5.0, 1.0, 2.0));
  EXPECT_EQ(MultiplyPolynomials(a, Eigen::VectorXd()).size(), 0);
  EXPECT_EQ(TrimLeadingZeros(Eigen::Vector4d(1e-20, 0.0, 1.0, 2.0)), Eigen::Vector2d(1.0, 2.0));
}

// Round trips over random real polynomials whose roots span several decades, the case the
// balancing and the variable scaling are there for.
TEST(Polynomial, RootsRoundTripOverRandomWideRangePolynomials) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> decade(-1.0, 1.5);
  std::uniform_real_distribution<double> angle(0.1, 3.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Complex> roots;
    for (int k = 0; k < 3; ++k) {
      const Complex r = std::polar(std::pow(10.0, decade(rng)), angle(rng));
      roots.push_back(r);
      roots.push_back(std::conj(r));
    }
    roots.emplace_back(-std::pow(10.0, decade(rng)), 0.0);
    const Eigen::VectorXd p = PolynomialFromRoots(roots) * 3.0;
    const std::vector<Complex> found = PolynomialRoots(p);
    ASSERT_EQ(found.size(), roots.size());
    for (const Complex& r : roots) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Complex& f : found) nearest = std::min(nearest, std::abs(f - r) / std::abs(r));
      EXPECT_LT(nearest, 1e-7) << "trial " << trial << " root " << r;
    }
    for (std::size_t i = 0; i + 1 < found.size(); ++i) {
      EXPECT_LE(found[i].real(), found[i + 1].real());
    }
  }
}

TEST(Polynomial, ZeroRootsAreExactAndConstantsHaveNone) {
  const std::vector<Complex> r = PolynomialRoots(Eigen::Vector4d(1.0, -1.0, 0.0, 0.0));
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0], Complex(0.0, 0.0));
  EXPECT_EQ(r[1], Complex(0.0, 0.0));
  EXPECT_NEAR(r[2].real(), 1.0, 1e-15);
  EXPECT_TRUE(PolynomialRoots(Eigen::VectorXd::Constant(1, 4.0)).empty());
  EXPECT_EQ(SpectralRadius(Eigen::VectorXd::Constant(1, 4.0)), 0.0);
  Eigen::VectorXcd as_vector(2);
  as_vector << Complex(1.0, 2.0), Complex(1.0, -2.0);
  EXPECT_EQ(PolynomialFromRoots(as_vector), Eigen::Vector3d(1.0, -2.0, 5.0));
}

TEST(Polynomial, StabilizeReflectsUnstableRoots) {
  // Roots 2 and 0.5 in z: 2 goes to 1/2.
  const Eigen::Vector3d a(1.0, -2.5, 1.0);
  EXPECT_NEAR(SpectralRadius(a), 2.0, 1e-14);
  const Eigen::VectorXd s = StabilizeDiscrete(a);
  EXPECT_LT(SpectralRadius(s), 1.0);
  EXPECT_NEAR(s[1], -1.0, 1e-12);
  EXPECT_NEAR(s[2], 0.25, 1e-12);
  const Eigen::Vector3d stable(1.0, -0.5, 0.06);
  EXPECT_EQ(StabilizeDiscrete(stable), Eigen::VectorXd(stable));

  // s² - s - 2 = (s - 2)(s + 1) keeps its leading coefficient and mirrors 2 to -2.
  const Eigen::VectorXd c = StabilizeContinuous(Eigen::Vector3d(3.0, -3.0, -6.0));
  for (const Complex& r : PolynomialRoots(c)) EXPECT_LT(r.real(), 0.0);
  EXPECT_NEAR(c[0], 3.0, 1e-14);
  EXPECT_NEAR(c[1], 9.0, 1e-12);
  EXPECT_NEAR(c[2], 6.0, 1e-12);
}

TEST(Filter, MatchesTheDifferenceEquation) {
  const Eigen::Vector2d num(0.5, 0.25);
  const Eigen::Vector2d den(2.0, -1.0);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(6);
  x[0] = 1.0;
  x[3] = -2.0;
  const Eigen::VectorXd y = Filter(num, den, x);
  double y_prev = 0.0;
  double x_prev = 0.0;
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    const double expected = (0.5 * x[t] + 0.25 * x_prev + y_prev) / 2.0;
    EXPECT_DOUBLE_EQ(y[t], expected) << t;
    y_prev = expected;
    x_prev = x[t];
  }
  EXPECT_THROW(Filter(num, Eigen::Vector2d(0.0, 1.0), x), InputError);
}

// The plain difference equation, in the summation order Filter documents (the input taps in order,
// then the feedback taps oldest first): Filter's fixed-tap kernels and its general loop must give
// the same bits for every order, and FilterPair the bits of two Filter calls.
Eigen::VectorXd ReferenceFilter(const Eigen::VectorXd& num, const Eigen::VectorXd& den,
                                const Eigen::VectorXd& x) {
  Eigen::VectorXd y(x.size());
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    double acc = 0.0;
    for (Eigen::Index k = 0; k < num.size() && k <= t; ++k) acc += num[k] * x[t - k];
    for (Eigen::Index k = std::min(den.size() - 1, t); k >= 1; --k) acc -= den[k] * y[t - k];
    y[t] = acc / den[0];
  }
  return y;
}

TEST(Filter, EveryOrderGivesTheBitsOfTheDifferenceEquation) {
  std::mt19937 gen(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd x1(300);
  Eigen::VectorXd x2(300);
  for (Eigen::Index i = 0; i < x1.size(); ++i) {
    x1[i] = normal(gen);
    x2[i] = normal(gen);
  }
  for (int nb = 1; nb <= 11; ++nb) {
    for (int na = 1; na <= 11; ++na) {
      for (const double a0 : {1.0, 1.5}) {
        Eigen::VectorXd num(nb);
        Eigen::VectorXd den(na);
        for (int k = 0; k < nb; ++k) num[k] = normal(gen);
        den[0] = a0;
        // Stable: feedback taps small enough that Σ|a_k| < a0.
        for (int k = 1; k < na; ++k) den[k] = 0.5 * a0 * normal(gen) / (na * 2.0);
        const Eigen::VectorXd y1 = ReferenceFilter(num, den, x1);
        const Eigen::VectorXd y2 = ReferenceFilter(num, den, x2);
        EXPECT_TRUE((Filter(num, den, x1).array() == y1.array()).all()) << nb << " " << na;
        Eigen::VectorXd p1;
        Eigen::VectorXd p2;
        FilterPair(num, den, x1, x2, p1, p2);
        EXPECT_TRUE((p1.array() == y1.array()).all()) << nb << " " << na << " pair";
        EXPECT_TRUE((p2.array() == y2.array()).all()) << nb << " " << na << " pair";
      }
    }
  }
  // Shorter than the warm-up: only the bounded loop runs.
  const Eigen::VectorXd num = Eigen::VectorXd::Ones(6);
  const Eigen::VectorXd den = (Eigen::VectorXd(4) << 1.0, 0.1, 0.1, 0.1).finished();
  EXPECT_TRUE(
      (Filter(num, den, x1.head(3)).array() == ReferenceFilter(num, den, x1.head(3)).array())
          .all());
}

}  // namespace
}  // namespace vibid::numerics
