// Real polynomials, their roots and rational filters, shared by the observer design (dob) and the
// model searches (sysid).
//
// A coefficient vector p = [p0, p1, ..., pn] is read highest power first: p0 xⁿ + ... + pn, as in
// scipy.signal and MATLAB for polynomials in s or z. A polynomial in the delay operator q⁻¹,
// A = [1, a1, ..., an] meaning 1 + a1 q⁻¹ + ... + an q⁻ⁿ, is the same vector: its roots in z are
// the roots of zⁿ + a1 zⁿ⁻¹ + ... + an.
#pragma once

#include <Eigen/Core>
#include <complex>
#include <vector>

namespace vibid::numerics {

using Complex = std::complex<double>;

/// p(x) at a complex point (Horner).
Complex EvaluatePolynomial(Eigen::Ref<const Eigen::VectorXd> p, Complex x);

/// Product of two polynomials (coefficient convolution; the same in either ordering convention).
Eigen::VectorXd MultiplyPolynomials(Eigen::Ref<const Eigen::VectorXd> a,
                                    Eigen::Ref<const Eigen::VectorXd> b);

/// Drops leading coefficients whose magnitude is at most `rel_tol` times the largest one.
Eigen::VectorXd TrimLeadingZeros(Eigen::Ref<const Eigen::VectorXd> p, double rel_tol = 1e-14);

/// Roots as eigenvalues of the balanced companion matrix of p with its variable scaled so the
/// coefficients are O(1); zeros at the origin are exact. Sorted by real, then imaginary part, so
/// complex roots come in adjacent conjugate pairs. A constant has no roots.
std::vector<Complex> PolynomialRoots(Eigen::Ref<const Eigen::VectorXd> p);

/// Monic polynomial with the given roots; complex roots must come in conjugate pairs (the
/// imaginary residue is dropped).
Eigen::VectorXd PolynomialFromRoots(const std::vector<Complex>& roots);
Eigen::VectorXd PolynomialFromRoots(Eigen::Ref<const Eigen::VectorXcd> roots);

/// Largest root magnitude (0 for a constant).
double SpectralRadius(Eigen::Ref<const Eigen::VectorXd> p);

/// Reflects the roots of a monic q⁻¹ polynomial outside the unit circle to 1/conj(z), keeping it
/// monic, so that the filter 1/p is stable; roots on or near the circle are pulled in to
/// `max_radius`.
Eigen::VectorXd StabilizeDiscrete(Eigen::Ref<const Eigen::VectorXd> p, double max_radius = 0.999);

/// Mirrors the roots of an s-polynomial with nonnegative real part into the left half plane; the
/// leading coefficient is kept.
Eigen::VectorXd StabilizeContinuous(Eigen::Ref<const Eigen::VectorXd> p);

/// y = (num/den) x in q⁻¹ with zero initial conditions (scipy.signal.lfilter). InputError when
/// den is empty or den[0] is 0.
Eigen::VectorXd Filter(Eigen::Ref<const Eigen::VectorXd> num, Eigen::Ref<const Eigen::VectorXd> den,
                       Eigen::Ref<const Eigen::VectorXd> x);

/// y1 = Filter(num, den, x1), y2 = Filter(num, den, x2), the same bits as two calls. Each recursion
/// is latency bound; run side by side they share the time of one.
void FilterPair(Eigen::Ref<const Eigen::VectorXd> num, Eigen::Ref<const Eigen::VectorXd> den,
                Eigen::Ref<const Eigen::VectorXd> x1, Eigen::Ref<const Eigen::VectorXd> x2,
                Eigen::VectorXd& y1, Eigen::VectorXd& y2);

}  // namespace vibid::numerics
