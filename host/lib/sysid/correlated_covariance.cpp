#include "vibid/sysid/correlated_covariance.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/QR>

#include "vibid/common/error.hpp"

namespace vibid::sysid {

namespace {

// Twice the first lag at which the autocorrelation of r falls below 2 / sqrt(N), at most N / 4.
int BartlettLags(const Eigen::Ref<const Eigen::VectorXd>& r) {
  const Eigen::Index n = r.size();
  const double r0 = r.squaredNorm();
  const Eigen::Index cap = std::max<Eigen::Index>(1, n / 4);
  if (!(r0 > 0.0)) return 0;
  const double bound = 2.0 / std::sqrt(static_cast<double>(n));
  for (Eigen::Index l = 1; l <= cap; ++l) {
    const double rho = r.head(n - l).dot(r.tail(n - l)) / r0;
    if (rho < bound) return static_cast<int>(std::min(cap, 2 * l - 1));
  }
  return static_cast<int>(cap);
}

}  // namespace

CorrelatedCovariance CovarianceForCorrelatedResiduals(Eigen::Ref<const Eigen::MatrixXd> jacobian,
                                                      Eigen::Ref<const Eigen::VectorXd> residual) {
  Require(jacobian.rows() == residual.size(), "covariance: Jacobian and residual differ in length");
  const Eigen::Index n = residual.size();
  const Eigen::Index p = jacobian.cols();
  CorrelatedCovariance out;
  out.lags = BartlettLags(residual);
  // Scores g_t = J_t^T r_t, one row per sample.
  const Eigen::MatrixXd g = jacobian.array().colwise() * residual.array();
  Eigen::MatrixXd s = g.transpose() * g;
  for (int l = 1; l <= out.lags; ++l) {
    const double w = 1.0 - static_cast<double>(l) / static_cast<double>(out.lags + 1);
    const Eigen::MatrixXd gamma = g.topRows(n - l).transpose() * g.bottomRows(n - l);
    s += w * (gamma + gamma.transpose());
  }
  // Small-sample factor N / (N - p), as sigma^2 = |r|^2 / (N - p) has.
  s *= static_cast<double>(n) / static_cast<double>(std::max<Eigen::Index>(n - p, 1));
  const Eigen::MatrixXd h_inv =
      (jacobian.transpose() * jacobian).eval().completeOrthogonalDecomposition().pseudoInverse();
  out.covariance = h_inv * s * h_inv.transpose();
  return out;
}

}  // namespace vibid::sysid
