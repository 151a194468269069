// Zero-pole-gain systems, their discretization (Tustin with pre-warping, zero-order hold) and the
// second-order-section cascades the fixed-point runtime runs.
#pragma once

#include <vector>

#include "vibid/numerics/polynomial.hpp"

namespace vibid::dob {

using Complex = numerics::Complex;

/// H(x) = gain * prod(x - zeros) / prod(x - poles); x is s (rad/s) or z. Complex roots come in
/// conjugate pairs so H is real.
struct Zpk {
  std::vector<Complex> zeros;
  std::vector<Complex> poles;
  double gain = 1.0;
};

Complex EvaluateZpk(const Zpk& zpk, Complex x);

/// Tustin: s = K (z - 1)/(z + 1) with K = omega_warp / tan(omega_warp / (2 fs)), so the discrete
/// response equals the analog one at omega_warp; omega_warp_rad_s = 0 gives K = 2 fs (no warping).
/// Zeros at infinity map to z = -1. Same algebra as scipy.signal.bilinear_zpk.
Zpk TustinZpk(const Zpk& analog, double fs_hz, double omega_warp_rad_s);

/// Zero-order hold (step invariance): poles exp(p T); zeros from the discretized state space
/// (transmission zeros by QZ); gain matched on the state space at a point away from the poles.
Zpk ZeroOrderHoldZpk(const Zpk& analog, double fs_hz);

/// y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2] (scipy sos row [b, 1, a1, a2]).
struct SosSection {
  double b0 = 0.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
};

/// Splits a discrete system (zeros <= poles) into sections: complex pairs kept together, each
/// pole pair given its nearest zeros, sections ordered by pole radius so the poles nearest the unit
/// circle come last; the gain goes into the first section.
std::vector<SosSection> ZpkToSos(const Zpk& digital);

Complex EvaluateSos(const std::vector<SosSection>& sos, Complex z);

/// State of the cascade before the first sample.
enum class SosStart {
  kZero,         ///< All delays zero (scipy.signal.sosfilt without zi).
  kSteadyState,  ///< Settled on a constant input equal to x[0] (sosfilt_zi scaled by x[0]).
};

/// Runs the cascade over x in double precision.
Eigen::VectorXd FilterSos(const std::vector<SosSection>& sos,
                          const Eigen::Ref<const Eigen::VectorXd>& x,
                          SosStart start = SosStart::kZero);

/// Largest pole radius of the cascade.
double MaxPoleRadius(const std::vector<SosSection>& sos);

}  // namespace vibid::dob
