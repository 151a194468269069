// Polynomials and rational filters in the delay operator q⁻¹ and in the Laplace variable s.
//
// Discrete polynomials are coefficient vectors in ascending powers of q⁻¹: A = [1, a1, ..., ana]
// means A(q) = 1 + a1 q⁻¹ + ... + ana q⁻ⁿᵃ. Continuous polynomials are in descending powers of s
// (highest first), as MATLAB's tf and scipy.signal write them.
#pragma once

#include <complex>

#include <Eigen/Core>

namespace vibid::sysid {

/// y = (num/den) x in q⁻¹ with zero initial conditions. den[0] must be nonzero.
Eigen::VectorXd Filter(Eigen::Ref<const Eigen::VectorXd> num, Eigen::Ref<const Eigen::VectorXd> den,
                       Eigen::Ref<const Eigen::VectorXd> x);

/// Product of two polynomials (coefficient convolution; same in either ordering convention).
Eigen::VectorXd PolyMul(Eigen::Ref<const Eigen::VectorXd> a, Eigen::Ref<const Eigen::VectorXd> b);

/// Roots of p. For a q⁻¹ polynomial [1, a1, ..., an] these are the poles in z (the same vector read
/// as z^n + a1 z^(n-1) + ...). Leading zeros are dropped; a constant has no roots.
Eigen::VectorXcd Roots(Eigen::Ref<const Eigen::VectorXd> p);

/// Monic polynomial (highest power first) with the given roots; complex roots must come in
/// conjugate pairs, the imaginary residue is dropped.
Eigen::VectorXd PolyFromRoots(Eigen::Ref<const Eigen::VectorXcd> roots);

/// Largest root magnitude of a q⁻¹ polynomial (0 for a constant).
double SpectralRadius(Eigen::Ref<const Eigen::VectorXd> p);

/// Reflects roots of a monic q⁻¹ polynomial outside the unit circle to 1/conj(z), keeping it monic,
/// so the filter 1/p is stable. Roots on the circle are pulled in to radius `max_radius`.
Eigen::VectorXd StabilizeDiscrete(Eigen::Ref<const Eigen::VectorXd> p, double max_radius = 0.999);

/// Mirrors roots of a monic s-polynomial with nonnegative real part into the left half plane.
Eigen::VectorXd StabilizeContinuous(Eigen::Ref<const Eigen::VectorXd> p);

/// Evaluates a polynomial in descending powers at a complex point.
std::complex<double> PolyVal(Eigen::Ref<const Eigen::VectorXd> p, std::complex<double> x);

}  // namespace vibid::sysid
