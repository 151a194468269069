// Goodness of fit and residual tests.
#pragma once

#include <Eigen/Core>

namespace vibid::sysid {

/// Normalised root-mean-square fit as MATLAB's compare reports it, in percent:
///   fit = 100 (1 − ‖y − ŷ‖ / ‖y − mean(y)‖).
/// 100 is a perfect model; 0 is no better than the mean; it can be negative. Lengths must match;
/// a constant y gives −∞ unless ŷ equals it (then 100).
double FitPercent(Eigen::Ref<const Eigen::VectorXd> y, Eigen::Ref<const Eigen::VectorXd> y_hat);

/// Two-sided standard normal quantile: z with P(|Z| ≤ z) = confidence.
double NormalQuantileTwoSided(double confidence);

/// The chi-square quantile with `dof` degrees of freedom at `probability` (numerics::
/// ChiSquareQuantile, within 1e-9 of scipy in its tests).
double ChiSquareQuantile(double probability, int dof);

/// Free-running validation of a model's residuals e (prediction or simulation errors) against its
/// input u (Ljung, System Identification, 2nd ed., §16.6).
struct ResidualTests {
  int max_lag = 0;
  double confidence = 0.0;
  Eigen::VectorXd autocorrelation;     ///< ρ_e(τ), τ = 1..max_lag (normalised by ρ_e(0)).
  double autocorrelation_bound = 0.0;  ///< z/√N: ρ_e of white residuals stays inside.
  int autocorrelation_outside = 0;
  double ljung_box = 0.0;            ///< Q = N(N+2) Σ ρ_e(τ)²/(N − τ).
  double ljung_box_threshold = 0.0;  ///< χ²(max_lag) quantile at `confidence`.
  bool white = false;                ///< Q below its threshold.

  Eigen::VectorXd cross_correlation;  ///< ρ_eu(τ), τ = −max_lag..max_lag (e lagging u for τ > 0).
  double cross_correlation_bound = 0.0;  ///< z √(Σ_k ρ_e(k) ρ_u(k) / N).
  int cross_correlation_outside = 0;
  /// S = Σ_τ (ρ_eu(τ)/σ)², σ = bound/z: χ²(2 max_lag + 1) distributed when e is independent of u.
  double cross_correlation_statistic = 0.0;
  double cross_correlation_threshold = 0.0;  ///< χ²(2 max_lag + 1) quantile at `confidence`.
  bool independent = false;                  ///< S below its threshold.
};

ResidualTests TestResiduals(Eigen::Ref<const Eigen::VectorXd> residual,
                            Eigen::Ref<const Eigen::VectorXd> input, int max_lag = 25,
                            double confidence = 0.99);

}  // namespace vibid::sysid
