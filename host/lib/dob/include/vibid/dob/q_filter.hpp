// The observer's Q-filter (methods Eq. 14) and the polynomial prototypes it is built from.
#pragma once

#include <Eigen/Core>

namespace vibid::dob {

enum class QPrototype {
  kButterworth,  ///< -3 dB at 1/tau for the all-pole case.
  kBinomial,     ///< (1 + tau s)^N: no overshoot in the step response, a softer corner.
};

/// Coefficients a_0..a_N (ascending powers, a_0 = a_N = 1) of the normalised Butterworth polynomial
/// of order N >= 1 (product formula a_k = a_{k-1} cos((k-1) pi/2N) / sin(k pi/2N)).
Eigen::VectorXd ButterworthCoefficients(int order);

/// Binomial coefficients C(N, k), k = 0..N.
Eigen::VectorXd BinomialCoefficients(int order);

/// Q(s) = (1 + sum_{k=1}^{N-r} a_k (tau s)^k) / (1 + sum_{k=1}^{N} a_k (tau s)^k).
struct QFilter {
  int order = 0;            ///< N
  int relative_degree = 0;  ///< r
  double tau_s = 0.0;
  Eigen::VectorXd prototype;  ///< a_0..a_N, ascending.
  Eigen::VectorXd num;        ///< Powers of s, highest first (degree N - r).
  Eigen::VectorXd den;        ///< Powers of s, highest first (degree N).
};

/// Builds Q. InputError unless N >= 1, 0 <= N - r (r >= 0) and tau_s > 0.
QFilter MakeQFilter(int order, int relative_degree, double tau_s,
                    QPrototype prototype = QPrototype::kButterworth);

}  // namespace vibid::dob
