// Parameter covariance of a least-squares fit whose residuals are correlated in time.
//
// sigma^2 (J^T J)^-1 holds for white residuals. An output-error fit of a rig with dry friction
// leaves residuals that run for hundreds of samples one way (the friction the linear model cannot
// follow), and that covariance is then too small by about the residuals' correlation length: on
// the ECP cart, M +- 0.3 % where repeated runs spread 3.9 %. The sandwich form
// (J^T J)^-1 S (J^T J)^-1, with S the long-run covariance of the scores g_t = J_t^T r_t summed
// with Bartlett weights 1 - l / (L + 1) over lags l <= L (Newey and West, Econometrica 55, 1987),
// holds for correlated residuals; L is twice the lag at which the residuals' autocorrelation first
// falls inside its white-noise bound 2 / sqrt(N) (at most N / 4).
#pragma once

#include <Eigen/Core>

namespace vibid::sysid {

struct CorrelatedCovariance {
  Eigen::MatrixXd covariance;
  int lags = 0;  ///< L, the Bartlett window's last lag.
};

/// The sandwich covariance for `jacobian` (N x p, of the residuals) and `residual` (N).
CorrelatedCovariance CovarianceForCorrelatedResiduals(Eigen::Ref<const Eigen::MatrixXd> jacobian,
                                                      Eigen::Ref<const Eigen::VectorXd> residual);

}  // namespace vibid::sysid
