// SSI-cov's interval samples propagated the textbook way, as the reference of the fast path in
// SsiCov: every sample's Hankel matrix through its own SVD, O = U_n S_n^½, A by least squares
// (column-pivoted QR), the full eigensolver for every pole and shape (Reynders, Pintelon &
// De Roeck, MSSP 22(4) 2008, sampled). The same samples (seed, weights) and the same rule for
// finding a mode again, so the half-widths agree with SsiCov's to rounding.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "vibid/oma/ssi_cov.hpp"

namespace vibid::oma::testing {

struct TextbookInterval {
  double omega_ci95_rad_s = 0.0;
  double zeta_ci95 = 0.0;
  Eigen::VectorXd shape_ci95;
  double found_share = 0.0;
};

/// One per mode of `result`, which SsiCov(y, options) returned.
std::vector<TextbookInterval> TextbookIntervals(Eigen::Ref<const Eigen::MatrixXd> y,
                                                const SsiCovOptions& options,
                                                const SsiCovResult& result);

}  // namespace vibid::oma::testing
