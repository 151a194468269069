// Eigenvalues of a real square matrix, and the eigenvector of any one of them on request, for
// callers that need every eigenvalue but only a few eigenvectors (the poles of a state matrix, the
// shapes of those near a mode): the matrix is reduced to Hessenberg form once, its eigenvalues
// come from the Francis double-shift QR iteration on the unreduced block alone (no Schur form, no
// Schur vectors: Wilkinson & Reinsch, Handbook for Automatic Computation II, 1971, procedure
// hqr), and an eigenvector from inverse iteration on the Hessenberg form, O(n²) per vector.
#pragma once

#include <complex>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace vibid::numerics {

class HessenbergEigen {
 public:
  /// `a` square and finite.
  explicit HessenbergEigen(const Eigen::MatrixXd& a);

  /// False when the iteration did not converge (then eigenvalues() is empty).
  bool ok() const { return ok_; }
  /// Every eigenvalue, complex pairs adjacent (+ imaginary part first); no other order.
  const Eigen::VectorXcd& eigenvalues() const { return eigenvalues_; }
  /// A unit eigenvector of `lambda`, one of eigenvalues(); its phase is arbitrary. Inverse
  /// iteration with a shift a relative 1e-10 off `lambda` (exactly on it the factor is singular):
  /// each step shrinks the other eigenvectors' share by that offset over their gap to `lambda`.
  Eigen::VectorXcd Eigenvector(std::complex<double> lambda) const;

 private:
  Eigen::HessenbergDecomposition<Eigen::MatrixXd> hessenberg_;
  Eigen::MatrixXd h_;  // the Hessenberg form, kept for the eigenvectors
  Eigen::VectorXcd eigenvalues_;
  bool ok_ = false;
};

}  // namespace vibid::numerics
