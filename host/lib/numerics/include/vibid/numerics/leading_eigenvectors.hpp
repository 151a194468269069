// The eigenvectors of the largest eigenvalues of a real symmetric matrix, for callers that need
// a leading eigenspace and not the rest (the leading left singular vectors of a Hankel matrix from
// h hᵀ): the matrix is reduced to tridiagonal form, its eigenvalues come from the implicit QR
// iteration without eigenvectors, and the wanted eigenvectors from inverse iteration on the
// tridiagonal form, reorthogonalized within clusters of close eigenvalues (the method of LAPACK's
// dstein: Dhillon, "Current inverse iteration software can fail", BIT 38, 1998, describes its
// limits). The QR iteration with eigenvectors rotates every eigenvector at every step, which costs
// most of a full solve; inverse iteration costs O(n) per step and vector plus the
// reorthogonalization. Each vector's residual is checked, and where inverse iteration does not
// reach it the full solver (Eigen's SelfAdjointEigenSolver) gives the vectors instead.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace vibid::numerics {

/// How the last Compute ended.
enum class LeadingEigenTermination {
  kInverseIteration,  ///< every vector by inverse iteration within the residual bound
  kFullSolver,        ///< a vector missed the bound: all of them from the full solver
  kFailed,            ///< the eigenvalue iteration did not converge (vectors() is empty)
};

class LeadingEigenvectors {
 public:
  /// The unit eigenvectors of the `count` largest eigenvalues of the symmetric matrix whose lower
  /// triangle `lower` holds (the upper is not read), in descending order of the eigenvalues:
  /// orthonormal to rounding, so each leading block of columns spans the leading eigenspace of its
  /// size. 1 ≤ count ≤ n; `lower` finite.
  void Compute(const Eigen::MatrixXd& lower, int count);

  LeadingEigenTermination termination() const { return termination_; }
  bool ok() const { return termination_ != LeadingEigenTermination::kFailed; }
  /// n × count, columns in descending order of their eigenvalues.
  const Eigen::MatrixXd& vectors() const { return vectors_; }
  /// The `count` largest eigenvalues, descending.
  const Eigen::VectorXd& values() const { return values_; }

  /// A vector is accepted when ‖T z − λ z‖ is at most this times n ε ‖T‖₁ (T tridiagonal,
  /// z unit): the residual the QR iteration itself leaves, with a margin.
  static constexpr double kResidualFactor = 4.0;

 private:
  bool InverseIteration(int count);

  Eigen::MatrixXd scaled_;
  Eigen::Tridiagonalization<Eigen::MatrixXd> tridiagonal_;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> tridiagonal_values_;
  Eigen::VectorXd diag_, sub_;
  Eigen::MatrixXd z_;          // the eigenvectors of the tridiagonal form
  Eigen::VectorXd workspace_;  // a reflector's row of products
  // LU of T − σI with partial pivoting (LAPACK dgttrf's layout; lu_d_ ends as the pivots'
  // reciprocals).
  Eigen::VectorXd lu_d_, lu_du_, lu_du2_, lu_dl_, x_;
  Eigen::VectorXi pivot_;
  Eigen::MatrixXd vectors_;
  Eigen::VectorXd values_;
  LeadingEigenTermination termination_ = LeadingEigenTermination::kFailed;
};

}  // namespace vibid::numerics
