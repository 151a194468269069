#include "vibid/sysid/fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"

namespace vibid::sysid {

double FitPercent(Eigen::Ref<const Eigen::VectorXd> y, Eigen::Ref<const Eigen::VectorXd> y_hat) {
  Require(y.size() == y_hat.size() && y.size() > 0,
          "fit: measured and model outputs differ in length");
  const double err = (y - y_hat).norm();
  const double spread = (y.array() - y.mean()).matrix().norm();
  if (spread == 0.0) return err == 0.0 ? 100.0 : -std::numeric_limits<double>::infinity();
  return 100.0 * (1.0 - err / spread);
}

double NormalQuantileTwoSided(double confidence) {
  Require(confidence > 0.0 && confidence < 1.0, "confidence must lie strictly between 0 and 1");
  return numerics::NormalQuantile(0.5 + 0.5 * confidence);
}

double ChiSquareQuantile(double probability, int dof) {
  Require(dof >= 1, "chi-square: degrees of freedom must be >= 1");
  Require(probability > 0.0 && probability < 1.0,
          "chi-square: the probability must lie strictly between 0 and 1");
  return numerics::ChiSquareQuantile(probability, dof);
}

namespace {

/// Normalised cross-covariance Σ a(t) b(t−τ) / (N σ_a σ_b) of zero-mean signals, τ may be negative.
double Correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b, Eigen::Index lag,
                   double norm) {
  const Eigen::Index n = a.size();
  double acc = 0.0;
  if (lag >= 0) {
    for (Eigen::Index t = lag; t < n; ++t) acc += a[t] * b[t - lag];
  } else {
    for (Eigen::Index t = 0; t < n + lag; ++t) acc += a[t] * b[t - lag];
  }
  return acc / norm;
}

}  // namespace

ResidualTests TestResiduals(Eigen::Ref<const Eigen::VectorXd> residual,
                            Eigen::Ref<const Eigen::VectorXd> input, int max_lag,
                            double confidence) {
  Require(residual.size() == input.size(), "residual test: residual and input differ in length");
  Require(max_lag >= 1 && residual.size() > 4 * max_lag,
          "residual test: need more than 4 x max_lag samples");
  const Eigen::Index n = residual.size();
  const Eigen::VectorXd e = residual.array() - residual.mean();
  const Eigen::VectorXd u = input.array() - input.mean();
  const double ee = e.squaredNorm();
  const double uu = u.squaredNorm();
  Require(ee > 0.0,
          "residual test: residuals are identically zero (a perfect fit has nothing to test)");
  Require(uu > 0.0, "residual test: the input is constant");
  ResidualTests t;
  t.max_lag = max_lag;
  t.confidence = confidence;
  const double z = NormalQuantileTwoSided(confidence);
  const double nd = static_cast<double>(n);

  t.autocorrelation.resize(max_lag);
  Eigen::VectorXd rho_u(max_lag);
  for (int k = 1; k <= max_lag; ++k) {
    t.autocorrelation[k - 1] = Correlation(e, e, k, ee);
    rho_u[k - 1] = Correlation(u, u, k, uu);
    t.ljung_box += t.autocorrelation[k - 1] * t.autocorrelation[k - 1] / (nd - k);
  }
  t.ljung_box *= nd * (nd + 2.0);
  t.autocorrelation_bound = z / std::sqrt(nd);
  t.autocorrelation_outside =
      static_cast<int>((t.autocorrelation.array().abs() > t.autocorrelation_bound).count());
  t.ljung_box_threshold = ChiSquareQuantile(confidence, max_lag);
  t.white = t.ljung_box < t.ljung_box_threshold;

  const double norm_eu = std::sqrt(ee * uu);
  t.cross_correlation.resize(2 * max_lag + 1);
  for (int k = -max_lag; k <= max_lag; ++k)
    t.cross_correlation[k + max_lag] = Correlation(e, u, k, norm_eu);
  // Variance of ρ_eu(τ) for e independent of u: (1/N) Σ_k ρ_e(k) ρ_u(k) (Ljung, eq. 16.67).
  const double p = std::max(1.0 + 2.0 * t.autocorrelation.dot(rho_u), 0.1);
  t.cross_correlation_bound = z * std::sqrt(p / nd);
  t.cross_correlation_outside =
      static_cast<int>((t.cross_correlation.array().abs() > t.cross_correlation_bound).count());
  const double sigma = std::sqrt(p / nd);
  t.cross_correlation_statistic = (t.cross_correlation / sigma).squaredNorm();
  t.cross_correlation_threshold = ChiSquareQuantile(confidence, 2 * max_lag + 1);
  t.independent = t.cross_correlation_statistic < t.cross_correlation_threshold;
  return t;
}

}  // namespace vibid::sysid
