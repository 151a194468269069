// Model updating from test results: effective mass from a 1-DOF hammer test (methods §6) and
// stiffness from modal test data (methods §7, Eq. 7).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "vibid/ident/intervals.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/peaks.hpp"
#include "vibid/ident/spectral.hpp"
#include "vibid/numerics/least_squares.hpp"

namespace vibid::ident {

struct MassUpdateOptions {
  /// Known spring stiffness; 0 fits it together with the mass.
  double k_n_per_m = 0.0;
  /// Nominal (datasheet) mass for the % change; 0 when unknown.
  double nominal_kg = 0.0;
  /// Fitted band: omega within (1 +- band_fraction) omega_peak.
  double band_fraction = 0.3;
  bool coherence_weighting = true;
  /// Refine the damping in the fit too, started from the half-power value. Guide friction and a
  /// short record widen the half-power band; a c held at that value then drags m and k (both
  /// low by the same factor). false keeps c at the half-power value (methods §6 as written).
  bool fit_damping = true;
  PeakOptions peaks;
  numerics::SolverOptions solver{
      .max_iterations = 100, .function_tolerance = 1e-14, .parameter_tolerance = 1e-12};

  void Validate() const;
};

struct MassUpdateResult {
  double mass_kg = 0.0;    ///< Effective mass.
  double k_n_per_m = 0.0;  ///< As given, or fitted.
  bool stiffness_fitted = false;
  bool damping_fitted = false;
  double zeta = 0.0;             ///< c / (2 sqrt(k m)): fitted, or the half-power value.
  double zeta_half_power = 0.0;  ///< Half-power damping (exponential-window correction applied).
  double c_ns_per_m = 0.0;       ///< Viscous damping of the mass alone (window damping removed).
  double omega_rad_s = 0.0;      ///< Peak-picked resonance.
  double nominal_kg = 0.0;
  double change_percent = 0.0;  ///< 100 (m - nominal) / nominal; 0 without a nominal.
  std::size_t lines_fitted = 0;
  /// Uncertainties from the fit's covariance, sigma^2 (J^T J)^-1 with sigma^2 from the residuals
  /// (lines - parameters degrees of freedom); a quantity that was given or held (k given, c at
  /// its half-power value) has none and says so.
  Uncertainty mass_u, k_u, c_u;
  numerics::SolverSummary summary;
  std::vector<std::string> warnings;
};

/// Fits |H| = 1 / sqrt((k - m omega^2)^2 + (c omega)^2) (Eq. 6) to the receptance magnitude of
/// `response` over a band around the largest resonance: coherence-weighted log magnitude,
/// Levenberg–Marquardt, c started from the half-power damping (2 zeta sqrt(k m)) and refined
/// unless options.fit_damping is false. An exponential window on the records adds 2 m / tau to
/// the damping the windowed FRF shows; the fit models it and reports c without it.
MassUpdateResult UpdateMass(const Frf& receptance, std::size_t response,
                            const MassUpdateOptions& options);

/// Stiffness (and damping) matrices from one modal test, chain springs by the source's
/// convention and by least squares.
struct StiffnessUpdateResult {
  Eigen::MatrixXd k_matrix;     ///< K = M Phi Omega^2 Phi^T M.
  Eigen::MatrixXd c_matrix;     ///< C = M Phi diag(2 zeta omega) Phi^T M.
  Eigen::VectorXd springs;      ///< k_n = K_nn, k_i = K_ii - k_{i+1} (k2 = K22, k1 = K11 - K22).
  Eigen::VectorXd springs_lsq;  ///< Chain springs closest to K in the Frobenius norm.
  Eigen::VectorXd dampers;      ///< Same convention as `springs`, from C.
  /// 100 (-K_{i-1,i} - k_i) / k_i, largest in magnitude over the chain links (2-DOF: -K12 vs k2).
  double offdiag_mismatch_percent = 0.0;
};

/// `shapes` n x n (one column per mode, any scaling; mass-normalised here with `masses_kg`),
/// `omega_rad_s` and `zeta` one per mode. InputError on size mismatch or a zero shape.
StiffnessUpdateResult UpdateStiffness(const Eigen::Ref<const Eigen::VectorXd>& masses_kg,
                                      const Eigen::Ref<const Eigen::VectorXd>& omega_rad_s,
                                      const Eigen::Ref<const Eigen::VectorXd>& zeta,
                                      const Eigen::Ref<const Eigen::MatrixXd>& shapes);

/// Jacobian of the update map (x -> chain springs and dampers of UpdateStiffness) by central
/// differences, for the delta method. Inputs x = [masses (n), omega (n), zeta (n), shapes (n x n,
/// column by column)]; rows: springs (n), then dampers (n).
Eigen::MatrixXd StiffnessJacobian(const Eigen::Ref<const Eigen::VectorXd>& masses_kg,
                                  const Eigen::Ref<const Eigen::VectorXd>& omega_rad_s,
                                  const Eigen::Ref<const Eigen::VectorXd>& zeta,
                                  const Eigen::Ref<const Eigen::MatrixXd>& shapes);

/// 2-DOF form: shape i = [ratio_i, 1].
StiffnessUpdateResult UpdateStiffness2(double m1_kg, double m2_kg,
                                       const std::vector<ModeEstimate>& modes);

/// Several tests updated separately, then averaged.
struct StiffnessAverage {
  std::vector<StiffnessUpdateResult> tests;
  Eigen::MatrixXd k_matrix;     ///< Mean.
  Eigen::VectorXd springs;      ///< Mean.
  Eigen::VectorXd springs_lsq;  ///< Mean.
  Eigen::VectorXd dampers;      ///< Mean.
  Eigen::VectorXd spread;       ///< Sample standard deviation of `springs` (0 for one test).
  double offdiag_mismatch_percent = 0.0;  ///< Mean.
};

StiffnessAverage AverageStiffness(const std::vector<StiffnessUpdateResult>& tests);

/// A mode's 95 % interval (value +- 1.96 sd: the modal model's are normal, large-sample) as an
/// uncertainty; not known when the mode has none (--method fit or peaks).
Uncertainty ModeIntervalUncertainty(const std::array<double, 2>& ci95);

/// Uncertainties of the averaged chain springs and dampers (AverageStiffness of `updates`), one
/// per position. Each test's values move with its modes' omega, zeta and a1/a2 (their intervals,
/// taken as independent: the modal model's correlations between them are not carried) through
/// the update map's Jacobian (StiffnessJacobian, masses held); the tests combine as repeats
/// (MeanOfRepeats); then the masses' share through the tests' mean Jacobian, since the same
/// masses enter every test. Shapes of more than two responses carry no interval, so there the
/// modes' share is the tests' scatter alone. `modes[t]` are the modes `updates[t]` came from.
struct ChainUncertainty {
  std::vector<Uncertainty> springs;
  std::vector<Uncertainty> dampers;
};
ChainUncertainty StiffnessUncertainty(const Eigen::VectorXd& masses_kg,
                                      const std::vector<Uncertainty>& masses_u,
                                      const std::vector<std::vector<ModeEstimate>>& modes,
                                      const std::vector<StiffnessUpdateResult>& updates);

}  // namespace vibid::ident
