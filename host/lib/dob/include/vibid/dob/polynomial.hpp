// Real polynomials and their roots, the bookkeeping under the observer design. Coefficients are
// stored highest power first, as in scipy.signal and the CLI's JSON.
#pragma once

#include <complex>
#include <vector>

#include <Eigen/Core>

namespace vibid::dob {

using Complex = std::complex<double>;

/// p(x) at a complex point (Horner).
Complex EvaluatePolynomial(const Eigen::Ref<const Eigen::VectorXd>& coeffs, Complex x);

/// Product of two polynomials.
Eigen::VectorXd MultiplyPolynomials(const Eigen::Ref<const Eigen::VectorXd>& a,
                                    const Eigen::Ref<const Eigen::VectorXd>& b);

/// Drops leading coefficients whose magnitude is below `rel_tol` times the largest one.
Eigen::VectorXd TrimLeadingZeros(const Eigen::Ref<const Eigen::VectorXd>& coeffs,
                                 double rel_tol = 1e-14);

/// Roots from the companion matrix's eigenvalues; complex roots come in conjugate pairs, sorted.
std::vector<Complex> PolynomialRoots(const Eigen::Ref<const Eigen::VectorXd>& coeffs);

/// Monic polynomial with the given roots (conjugate pairs expected: the result is real).
Eigen::VectorXd PolynomialFromRoots(const std::vector<Complex>& roots);

}  // namespace vibid::dob
