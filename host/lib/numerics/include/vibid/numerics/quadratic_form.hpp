// The upper tail of a positive quadratic form in Gaussian variables, Q = Σ wᵢ (zᵢ + δᵢ)² with zᵢ
// independent standard normal, wᵢ > 0: the law of a Hotelling statistic whose mean and covariance
// are not the ones it was scaled with (a reference's estimates against the truth). By the
// Lugannani–Rice saddlepoint formula (Lugannani & Rice, Adv. Appl. Prob. 12 1980; for quadratic
// forms Kuonen, Biometrika 86 1999), whose relative error stays at a few per cent however far
// out the tail is, where Imhof's integral loses its digits below about 1e-8.
#pragma once

#include <Eigen/Core>

namespace vibid::numerics {

/// P(Q > h) for weights w > 0 and noncentralities δ (same size), h > 0.
double QuadraticFormTail(const Eigen::VectorXd& weights, const Eigen::VectorXd& noncentrality,
                         double h);

}  // namespace vibid::numerics
