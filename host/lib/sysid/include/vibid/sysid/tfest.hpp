// Continuous-time transfer-function estimation from sampled data (like MATLAB's tfest).
//
//   y(t_k) = B(s)/A(s) u + P(s)/A(s) δ + e(t_k),  A = s^np + a_{np-1} s^{np-1} + ... + a_0,
//   B = b_nz s^nz + ... + b_0,  P = initial-condition polynomial (degree np − 1, or zero)
//
// Steps: (1) state-variable-filter least squares with the prefilter 1/(s + λ)^np for a few λ across
// the band; the best by simulation fit is iterated to convergence by SRIVC (Young's simplified
// refined instrumental variable method for continuous-time models); (2) that start is refined by
// output-error Levenberg–Marquardt on the exact ZOH simulation, so noise-free stepped data are
// fitted exactly.
// The Jacobian is exact too: ∂ŷ/∂b_k = ZOH(s^k/A) u, ∂ŷ/∂a_k = −ZOH(s^k B/A²) u − imp(s^k P/A²),
// ∂ŷ/∂p_k = imp(s^k/A), every one of them read from the states of 1/A and 1/A².
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>

#include "vibid/numerics/least_squares.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/io_data.hpp"

namespace vibid::sysid {

enum class InitialCondition { kZero, kEstimate };
const char* InitialConditionName(InitialCondition ic);
InitialCondition ParseInitialCondition(const std::string& name);

struct TfestOptions {
  int np = 2;  ///< Number of poles.
  int nz = 0;  ///< Number of zeros, < np.
  InitialCondition ic = InitialCondition::kZero;
  int srivc_iterations = 30;       ///< SRIVC passes of the chosen start.
  double srivc_tolerance = 1e-10;  ///< Relative parameter change that ends SRIVC.
  bool refine = true;  ///< Output-error refinement after SRIVC (false: SRIVC only, no covariance).
  numerics::SolverOptions solver;
  /// Throws InputError naming the first bad option.
  void Validate() const;
};

struct TfestResult {
  TransferFunction tf;     ///< Monic denominator, highest power first.
  Eigen::VectorXd ic_num;  ///< P(s), descending powers (np coefficients; zeros for kZero).
  /// Covariance of [a_{np-1}..a_0, b_nz..b_0, p_{np-1}..p_0] (the den tail, num, P when estimated).
  Eigen::MatrixXd covariance;
  Eigen::VectorXd den_std;  ///< Standard deviations of den (0 for the leading 1).
  Eigen::VectorXd num_std;
  double fit_percent = 0.0;  ///< Simulation fit on the estimation data, same IC handling.
  double noise_variance = 0.0;
  std::string initialization;  ///< e.g. "svf(lambda=12.57 rad/s)+srivc(7 iterations)".
  numerics::SolverSummary summary;
};

/// Estimates B/A from the record. InputError for bad options or orders too high for the record.
TfestResult EstimateTf(const IoData& data, const TfestOptions& options);

/// Simulated output of B/A from rest plus the free response of P/A (when `ic_num` is not empty).
Eigen::VectorXd SimulateWithIc(const TransferFunction& tf, Eigen::Ref<const Eigen::VectorXd> ic_num,
                               Eigen::Ref<const Eigen::VectorXd> u, double dt_s);

/// Initial-condition polynomial P (np coefficients) that best explains y − B/A u in least squares:
/// the free response is linear in P.
Eigen::VectorXd FitInitialCondition(const TransferFunction& tf, const IoData& data);

/// A map from free parameters θ to a monic continuous TF of fixed orders, for grey-box models.
/// `coefficients` gets [a_{np-1}..a_0, b_nz..b_0]; `jacobian` (when not null) its derivative in θ.
struct CtParameterization {
  int np = 2;
  int nz = 0;
  std::function<bool(const Eigen::VectorXd& theta, Eigen::VectorXd& coefficients,
                     Eigen::MatrixXd* jacobian)>
      map;
};

struct CtOeResult {
  Eigen::VectorXd theta;
  Eigen::VectorXd ic_num;
  Eigen::MatrixXd covariance;  ///< Of [θ, P] (P only with kEstimate), for white residuals.
  /// The same for residuals correlated in time (correlated_covariance.hpp), and its lags.
  Eigen::MatrixXd covariance_correlated;
  int correlation_lags = 0;
  Eigen::VectorXd residual;
  numerics::SolverSummary summary;
};

/// Output-error fit of a parameterised continuous TF (exact ZOH simulation, exact Jacobian).
CtOeResult FitContinuousOe(const IoData& data, const CtParameterization& param,
                           Eigen::Ref<const Eigen::VectorXd> theta0, InitialCondition ic,
                           const numerics::SolverOptions& options);

}  // namespace vibid::sysid
