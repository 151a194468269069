#include "vibid/numerics/hessenberg_eigen.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "vibid/common/error.hpp"

namespace vibid::numerics {
namespace {

using Complex = std::complex<double>;

// Each expected eigenvalue matched to a distinct computed one within `tol` (relative to its
// magnitude, at least 1).
void ExpectEigenvalues(const Eigen::VectorXcd& got, const std::vector<Complex>& expected,
                       double tol) {
  ASSERT_EQ(got.size(), static_cast<Eigen::Index>(expected.size()));
  std::vector<bool> used(expected.size(), false);
  for (const Complex e : expected) {
    double best = 1e300;
    Eigen::Index at = -1;
    for (Eigen::Index k = 0; k < got.size(); ++k) {
      if (used[static_cast<std::size_t>(k)]) continue;
      if (std::abs(got(k) - e) < best) {
        best = std::abs(got(k) - e);
        at = k;
      }
    }
    ASSERT_GE(at, 0);
    used[static_cast<std::size_t>(at)] = true;
    EXPECT_LT(best, tol * std::max(1.0, std::abs(e))) << "eigenvalue " << e;
  }
}

// A v = λ v for the eigenvector of every eigenvalue, to rounding.
void ExpectEigenvectors(const Eigen::MatrixXd& a, const HessenbergEigen& eig, double tol) {
  for (Eigen::Index k = 0; k < eig.eigenvalues().size(); ++k) {
    const Complex lambda = eig.eigenvalues()(k);
    const Eigen::VectorXcd v = eig.Eigenvector(lambda);
    EXPECT_NEAR(v.norm(), 1.0, 1e-12);
    const double residual = (a.cast<Complex>() * v - lambda * v).norm();
    EXPECT_LT(residual, tol * a.norm()) << "eigenvalue " << lambda;
  }
}

// A similarity S B S⁻¹ of a block-diagonal B with 2×2 blocks [[a, b], [−b, a]] (eigenvalues
// a ± ib, by construction) and real diagonal entries: the eigenvalues are B's.
TEST(HessenbergEigen, SimilarityOfKnownBlocks) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int n : {3, 8, 18, 40}) {
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n, n);
    std::vector<Complex> expected;
    int k = 0;
    for (; k + 1 < n; k += 2) {
      // Poles of a lightly damped discrete system: |λ| just below 1, as in a state matrix.
      const Complex lambda = std::polar(0.9 + 0.09 * std::fabs(uniform(rng)),
                                        std::numbers::pi * std::fabs(uniform(rng)));
      b(k, k) = b(k + 1, k + 1) = lambda.real();
      b(k, k + 1) = lambda.imag();
      b(k + 1, k) = -lambda.imag();
      expected.push_back(lambda);
      expected.push_back(std::conj(lambda));
    }
    if (k < n) {
      b(k, k) = uniform(rng);
      expected.emplace_back(b(k, k), 0.0);
    }
    Eigen::MatrixXd s(n, n);
    for (Eigen::Index i = 0; i < s.size(); ++i) s.data()[i] = normal(rng);
    s += 3.0 * Eigen::MatrixXd::Identity(n, n);  // well conditioned
    const Eigen::MatrixXd a = s * b * s.inverse();
    const HessenbergEigen eig(a);
    ASSERT_TRUE(eig.ok()) << n;
    ExpectEigenvalues(eig.eigenvalues(), expected, 1e-9);
    ExpectEigenvectors(a, eig, 1e-9);
  }
}

// The cyclic shift of 6 entries: its eigenvalues are the sixth roots of unity, all of one
// magnitude, where the standard double shift makes no progress and the exceptional shifts must
// break the cycle.
TEST(HessenbergEigen, CyclicShiftNeedsTheExceptionalShift) {
  const int n = 6;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 1; i < n; ++i) a(i, i - 1) = 1.0;
  a(0, n - 1) = 1.0;
  std::vector<Complex> expected;
  for (int k = 0; k < n; ++k) expected.push_back(std::polar(1.0, 2.0 * std::numbers::pi * k / n));
  const HessenbergEigen eig(a);
  ASSERT_TRUE(eig.ok());
  ExpectEigenvalues(eig.eigenvalues(), expected, 1e-12);
  ExpectEigenvectors(a, eig, 1e-9);
}

// The companion matrix of (z − 1)(z − 2)(z − 3)(z² + 1): roots 1, 2, 3, ± i.
TEST(HessenbergEigen, CompanionMatrixRoots) {
  // z⁵ − 6z⁴ + 12z³ − 12z² + 11z − 6
  const Eigen::VectorXd p = (Eigen::VectorXd(5) << -6.0, 12.0, -12.0, 11.0, -6.0).finished();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(5, 5);
  a.row(0) = -p.transpose();
  for (int i = 1; i < 5; ++i) a(i, i - 1) = 1.0;
  const HessenbergEigen eig(a);
  ASSERT_TRUE(eig.ok());
  ExpectEigenvalues(eig.eigenvalues(), {1.0, 2.0, 3.0, Complex(0.0, 1.0), Complex(0.0, -1.0)},
                    1e-11);
  ExpectEigenvectors(a, eig, 1e-9);
}

TEST(HessenbergEigen, SmallAndRefused) {
  EXPECT_EQ(HessenbergEigen(Eigen::MatrixXd(0, 0)).eigenvalues().size(), 0);
  const HessenbergEigen one(Eigen::MatrixXd::Constant(1, 1, -2.5));
  ASSERT_TRUE(one.ok());
  EXPECT_EQ(one.eigenvalues()(0), Complex(-2.5, 0.0));
  // [[0, 1], [−4, 0]]: ± 2i.
  const HessenbergEigen two((Eigen::Matrix2d() << 0.0, 1.0, -4.0, 0.0).finished());
  ExpectEigenvalues(two.eigenvalues(), {Complex(0.0, 2.0), Complex(0.0, -2.0)}, 1e-15);
  EXPECT_THROW(HessenbergEigen(Eigen::MatrixXd::Zero(2, 3)), InputError);
  EXPECT_THROW(HessenbergEigen(Eigen::MatrixXd::Constant(2, 2, std::nan(""))), InputError);
}

}  // namespace
}  // namespace vibid::numerics
