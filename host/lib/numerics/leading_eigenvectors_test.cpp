#include "vibid/numerics/leading_eigenvectors.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/QR>

#include "vibid/common/error.hpp"

namespace vibid::numerics {
namespace {

// A random orthogonal matrix (the Q of a Gaussian matrix's QR).
Eigen::MatrixXd RandomOrthogonal(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd g(n, n);
  for (Eigen::Index k = 0; k < g.size(); ++k) g.data()[k] = normal(rng);
  return g.householderQr().householderQ() * Eigen::MatrixXd::Identity(n, n);
}

// V diag(λ) Vᵀ with the eigenvalues given: the reference eigenvectors are V's columns, by
// construction. Only the lower triangle is handed over (the rest NaN: it must not be read).
struct Known {
  Eigen::MatrixXd lower;
  Eigen::MatrixXd v;  // columns in the order of `values`
  Eigen::VectorXd values;
};

Known Build(const Eigen::VectorXd& values, std::mt19937_64& rng) {
  const int n = static_cast<int>(values.size());
  Known k;
  k.v = RandomOrthogonal(n, rng);
  k.values = values;
  const Eigen::MatrixXd full = k.v * values.asDiagonal() * k.v.transpose();
  k.lower = Eigen::MatrixXd::Constant(n, n, std::nan(""));
  k.lower.triangularView<Eigen::Lower>() = full;
  return k;
}

// The largest principal angle's sine between span(a) and span(b) (orthonormal columns).
double SpanGap(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (b - a * (a.transpose() * b)).norm();
}

// Spectra of the kind h hᵀ has (a few large, the rest graded down by decades), with the
// eigenvalues descending: each leading eigenspace whose cut lies between separated eigenvalues
// matches the construction's, to rounding over the gap.
TEST(LeadingEigenvectors, GradedSpectraMatchTheConstruction) {
  std::mt19937_64 rng(5);
  for (int n : {2, 5, 18, 50}) {
    Eigen::VectorXd values(n);
    for (int k = 0; k < n; ++k) values(k) = std::pow(10.0, -12.0 * k / std::max(1, n - 1));
    const Known known = Build(values, rng);
    const int count = std::max(1, (4 * n) / 5);
    LeadingEigenvectors leading;
    leading.Compute(known.lower, count);
    ASSERT_EQ(leading.termination(), LeadingEigenTermination::kInverseIteration) << "n " << n;
    const Eigen::MatrixXd& u = leading.vectors();
    ASSERT_EQ(u.rows(), n);
    ASSERT_EQ(u.cols(), count);
    EXPECT_LT((u.transpose() * u - Eigen::MatrixXd::Identity(count, count)).norm(), 1e-13);
    for (int k = 0; k < count; ++k) {
      // Eigenvalue to rounding of the largest (absolute accuracy of a backward-stable solver).
      EXPECT_NEAR(leading.values()(k), values(k), 1e-14 * n) << "n " << n << " k " << k;
      // Each vector along the construction's: error ≤ ε‖A‖ / gap, the gap here ≥ 10^(-12/(n−1))
      // relative of the smaller, so a generous 1e-13 / gap.
      const double gap = values(k) - (k + 1 < n ? values(k + 1) : 0.0);
      const double along = std::fabs(u.col(k).dot(known.v.col(k)));
      EXPECT_NEAR(along, 1.0, std::max(1e-12, 1e-13 / gap)) << "n " << n << " k " << k;
    }
  }
}

// A cluster of equal and nearly equal eigenvalues within the count (vectors there are any
// orthonormal basis of the cluster's space): the leading spans at the cuts between clusters
// match, and the vectors stay orthonormal where inverse iteration alone would give parallel ones.
TEST(LeadingEigenvectors, ClustersGiveOrthonormalSpans) {
  std::mt19937_64 rng(7);
  const int n = 40;
  Eigen::VectorXd values(n);
  for (int k = 0; k < n; ++k) {
    if (k < 4) {
      values(k) = 10.0 - k;  // separated
    } else if (k < 12) {
      values(k) = 1.0;  // eight equal
    } else if (k < 20) {
      values(k) = 0.5 * (1.0 + 1e-9 * k);  // eight within 1e-8 relative
    } else {
      values(k) = 1e-3 / k;
    }
  }
  // Descending order for the spans below.
  std::sort(values.data(), values.data() + n, std::greater<>());
  const Known known = Build(values, rng);
  LeadingEigenvectors leading;
  leading.Compute(known.lower, 20);
  ASSERT_EQ(leading.termination(), LeadingEigenTermination::kInverseIteration);
  const Eigen::MatrixXd& u = leading.vectors();
  EXPECT_LT((u.transpose() * u - Eigen::MatrixXd::Identity(20, 20)).norm(), 1e-13);
  for (int cut : {4, 12, 20}) {
    EXPECT_LT(SpanGap(u.leftCols(cut), known.v.leftCols(cut)), 1e-12) << "cut " << cut;
  }
}

// The same vectors (up to sign) as Eigen's full solver on h hᵀ of a random Hankel-like matrix,
// whose eigenvalues are the squared singular values.
TEST(LeadingEigenvectors, AgreesWithTheFullSolverOnAGram) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd h(50, 50);
  for (Eigen::Index k = 0; k < h.size(); ++k) h.data()[k] = normal(rng);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(50, 50);
  gram.selfadjointView<Eigen::Lower>().rankUpdate(h);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> full(
      Eigen::MatrixXd(gram.selfadjointView<Eigen::Lower>()));
  LeadingEigenvectors leading;
  leading.Compute(gram, 40);
  ASSERT_EQ(leading.termination(), LeadingEigenTermination::kInverseIteration);
  for (int k = 0; k < 40; ++k) {
    const Eigen::VectorXd ref = full.eigenvectors().col(49 - k);
    const double gap =
        std::min(k > 0 ? full.eigenvalues()(50 - k) - full.eigenvalues()(49 - k) : 1e300,
                 full.eigenvalues()(49 - k) - full.eigenvalues()(48 - k));
    EXPECT_NEAR(std::fabs(leading.vectors().col(k).dot(ref)), 1.0,
                1e-13 * full.eigenvalues()(49) / gap)
        << "k " << k;
    EXPECT_NEAR(leading.values()(k), full.eigenvalues()(49 - k), 1e-13 * full.eigenvalues()(49));
  }
}

TEST(LeadingEigenvectors, RefusesBadArguments) {
  LeadingEigenvectors leading;
  EXPECT_THROW(leading.Compute(Eigen::MatrixXd::Identity(3, 4), 1), InputError);
  EXPECT_THROW(leading.Compute(Eigen::MatrixXd::Identity(3, 3), 0), InputError);
  EXPECT_THROW(leading.Compute(Eigen::MatrixXd::Identity(3, 3), 4), InputError);
  Eigen::MatrixXd bad = Eigen::MatrixXd::Identity(3, 3);
  bad(2, 1) = std::nan("");
  EXPECT_THROW(leading.Compute(bad, 2), InputError);
}

}  // namespace
}  // namespace vibid::numerics
