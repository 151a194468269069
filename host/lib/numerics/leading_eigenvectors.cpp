// Leading eigenvectors of a symmetric matrix by inverse iteration on its tridiagonal form (see the
// header for the method and its fallback).
#include "vibid/numerics/leading_eigenvectors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vibid/common/error.hpp"

namespace vibid::numerics {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Eigenvalues closer than this share of ‖T‖₁ form a cluster (dstein's ORTOL): each vector is
// reorthogonalized against its cluster's earlier ones once converged. Inverse iteration leaves
// two vectors at an eigenvalue distance δ apart non-orthogonal by about ε‖T‖/δ, 2e-13 at this
// distance; beyond it they are orthogonal to rounding already.
constexpr double kClusterShare = 1e-3;
// Closer than this share of ‖T‖₁, the start vector's part along an earlier vector shrinks by less
// than ε‖T‖/δ ≈ 2e-8 per step: those vectors are reorthogonalized at every step instead, as
// dstein does for its whole cluster, so that the step amplifies the wanted direction alone.
constexpr double kTightShare = 1e-8;
// Steps per vector: the first from the start vector, a second, then more until the residual
// holds, at most kMaxSteps.
constexpr int kMinSteps = 2;
constexpr int kMaxSteps = 6;

}  // namespace

void LeadingEigenvectors::Compute(const Eigen::MatrixXd& lower, int count) {
  Require(lower.rows() == lower.cols(), "leading eigenvectors: the matrix must be square");
  const Eigen::Index n = lower.rows();
  Require(count >= 1 && count <= n, "leading eigenvectors: count must lie in [1, n]");
  // Scaled to unit largest entry as Eigen's solver does (no overflow in the squares).
  scaled_ = lower.triangularView<Eigen::Lower>();
  Require(scaled_.allFinite(), "leading eigenvectors: the matrix holds a non-finite value");
  double scale = scaled_.cwiseAbs().maxCoeff();
  if (scale == 0.0) scale = 1.0;
  scaled_ /= scale;
  tridiagonal_.compute(scaled_);
  diag_ = tridiagonal_.diagonal();
  sub_ = tridiagonal_.subDiagonal();
  tridiagonal_values_.computeFromTridiagonal(diag_, sub_, Eigen::EigenvaluesOnly);
  if (tridiagonal_values_.info() == Eigen::Success && InverseIteration(count)) {
    values_ = tridiagonal_values_.eigenvalues().tail(count).reverse() * scale;
    // Back by Q = H₀ H₁ … H_{n−2}, the reflectors applied one by one (reflector k acts on
    // rows k+1 …, its essential part below the subdiagonal of the packed matrix): at these sizes
    // Eigen's blocked application builds its triangular factor for more than it saves.
    vectors_ = z_;
    workspace_.resize(vectors_.cols());
    for (Eigen::Index k = n - 2; k >= 0; --k) {
      vectors_.bottomRows(n - 1 - k).applyHouseholderOnTheLeft(
          tridiagonal_.packedMatrix().col(k).tail(n - 2 - k),
          tridiagonal_.householderCoefficients()(k), workspace_.data());
    }
    termination_ = LeadingEigenTermination::kInverseIteration;
    return;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> full(scaled_);
  if (full.info() != Eigen::Success) {
    termination_ = LeadingEigenTermination::kFailed;
    vectors_.resize(0, 0);
    values_.resize(0);
    return;
  }
  vectors_ = full.eigenvectors().rightCols(count).rowwise().reverse();
  values_ = full.eigenvalues().tail(count).reverse() * scale;
  termination_ = LeadingEigenTermination::kFullSolver;
}

bool LeadingEigenvectors::InverseIteration(int count) {
  const Eigen::Index n = diag_.size();
  const Eigen::VectorXd& ascending = tridiagonal_values_.eigenvalues();
  z_.resize(n, count);
  if (n == 1) {
    z_(0, 0) = 1.0;
    return true;
  }
  double norm = 0.0;  // ‖T‖₁
  for (Eigen::Index k = 0; k < n; ++k) {
    const double col = std::fabs(diag_(k)) + (k > 0 ? std::fabs(sub_(k - 1)) : 0.0) +
                       (k + 1 < n ? std::fabs(sub_(k)) : 0.0);
    norm = std::max(norm, col);
  }
  if (norm == 0.0) norm = 1.0;
  const double tiny = kEps * norm;  // a zero pivot's stand-in (dlagts's perturbation)
  const double residual_bound = kResidualFactor * static_cast<double>(n) * kEps * norm;
  lu_d_.resize(n);
  lu_du_.resize(n - 1);
  lu_dl_.resize(n - 1);
  lu_du2_.resize(std::max<Eigen::Index>(n - 2, 1));
  pivot_.resize(n - 1);
  x_.resize(n);
  Eigen::Index cluster_start = 0;  // the first vector of j's cluster
  Eigen::Index tight_start = 0;    // the first vector within kTightShare of j's eigenvalue
  double previous = 0.0;
  for (int j = 0; j < count; ++j) {
    const double exact = ascending(n - 1 - j);
    double sigma = exact;
    if (j > 0) {
      if (previous - sigma > kClusterShare * norm) cluster_start = j;
      while (tight_start < j && ascending(n - 1 - tight_start) - exact > kTightShare * norm) {
        ++tight_start;
      }
      // Equal eigenvalues would give the same vector: the shift is moved apart (dstein's PERTOL).
      const double apart = 10.0 * kEps * std::fabs(sigma);
      if (previous - sigma < apart) sigma = previous - apart;
    }
    previous = sigma;
    // LU of T − σI with partial pivoting, each step choosing between two rows (dgttrf).
    lu_d_ = diag_.array() - sigma;
    lu_du_ = sub_;
    lu_dl_ = sub_;
    for (Eigen::Index i = 0; i + 1 < n; ++i) {
      if (std::fabs(lu_d_(i)) >= std::fabs(lu_dl_(i))) {
        pivot_(i) = 0;
        if (lu_d_(i) == 0.0) lu_d_(i) = tiny;
        const double f = lu_dl_(i) / lu_d_(i);
        lu_dl_(i) = f;
        lu_d_(i + 1) -= f * lu_du_(i);
        if (i + 2 < n) lu_du2_(i) = 0.0;
      } else {
        pivot_(i) = 1;
        const double f = lu_d_(i) / lu_dl_(i);
        lu_d_(i) = lu_dl_(i);
        lu_dl_(i) = f;
        const double t = lu_du_(i);
        lu_du_(i) = lu_d_(i + 1);
        lu_d_(i + 1) = t - f * lu_d_(i + 1);
        if (i + 2 < n) {
          lu_du2_(i) = lu_du_(i + 1);
          lu_du_(i + 1) = -f * lu_du_(i + 1);
        }
      }
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      if (std::fabs(lu_d_(i)) < tiny) lu_d_(i) = std::copysign(tiny, lu_d_(i));
    }
    // The pivots' reciprocals: the back substitutions multiply (a division's latency would
    // chain through every row of every step).
    lu_d_ = lu_d_.cwiseInverse();
    // The first step solves U x = (1, …, 1) alone (its start vector is then P L (1, …, 1), with a
    // component along the wanted vector even where (1, …, 1) is another eigenvector: Wilkinson's
    // choice, as HessenbergEigen's).
    x_.setOnes();
    bool converged = false;
    for (int step = 0; step < kMaxSteps && !converged; ++step) {
      if (step > 0) {
        for (Eigen::Index i = 0; i + 1 < n; ++i) {
          if (pivot_(i) == 0) {
            x_(i + 1) -= lu_dl_(i) * x_(i);
          } else {
            const double t = x_(i);
            x_(i) = x_(i + 1);
            x_(i + 1) = t - lu_dl_(i) * x_(i);
          }
        }
      }
      x_(n - 1) *= lu_d_(n - 1);
      x_(n - 2) = (x_(n - 2) - lu_du_(n - 2) * x_(n - 1)) * lu_d_(n - 2);
      for (Eigen::Index i = n - 3; i >= 0; --i) {
        x_(i) = (x_(i) - lu_du_(i) * x_(i + 1) - lu_du2_(i) * x_(i + 2)) * lu_d_(i);
      }
      // Modified Gram–Schmidt against the close vectors so far at every step, against the whole
      // cluster's before the residual is judged.
      const bool judged = step + 1 >= kMinSteps;
      for (Eigen::Index k = judged ? cluster_start : tight_start; k < j; ++k) {
        x_ -= z_.col(k).dot(x_) * z_.col(k);
      }
      const double length = x_.norm();
      if (!(length > 0.0) || !std::isfinite(length)) return false;
      x_ /= length;
      if (!judged) continue;
      // ‖T x − λ x‖ against the eigenvalue itself (not the moved shift).
      double r2 = 0.0;
      for (Eigen::Index i = 0; i < n; ++i) {
        double t = (diag_(i) - exact) * x_(i);
        if (i > 0) t += sub_(i - 1) * x_(i - 1);
        if (i + 1 < n) t += sub_(i) * x_(i + 1);
        r2 += t * t;
      }
      converged = std::sqrt(r2) <= residual_bound;
    }
    if (!converged) return false;
    z_.col(j) = x_;
  }
  return true;
}

}  // namespace vibid::numerics
