// Free-decay analysis of pull-and-release records (no force channel): find the release, fit a
// damped sinusoid over the whole decay, and from a loaded/unloaded pair of the same spring solve
// for the stiffness and the base mass.
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "vibid/numerics/least_squares.hpp"

namespace vibid::ident {

struct DecayOptions {
  /// The fit stops where the envelope has fallen below this fraction of the first amplitude
  /// (friction and encoder quantization dominate the tail). 0 keeps the whole record.
  double end_fraction = 0.1;
  /// When > 0, fit only this many cycles after the release instead (guide friction makes the
  /// decay amplitude-dependent; the first cycles compare with a first-peaks log decrement).
  int cycles = 0;
  numerics::SolverOptions solver{
      .max_iterations = 200, .function_tolerance = 1e-14, .parameter_tolerance = 1e-12};

  void Validate() const;
};

struct DecayResult {
  /// First fitted sample: where the motion leaves the hold (within 1 % of the pull, so at most a
  /// sample or two after the true release on a noisy hold).
  std::size_t release_index = 0;
  double t_release_s = 0.0;  ///< Time from the record start.
  std::size_t fit_samples = 0;
  // x(t) = offset + amplitude exp(-sigma t) cos(omega_d t + phase), t from the release.
  double omega_d_rad_s = 0.0;
  double sigma_per_s = 0.0;
  double zeta = 0.0;
  double omega_n_rad_s = 0.0;
  double amplitude = 0.0;
  double phase_rad = 0.0;
  double offset = 0.0;
  double rms_residual = 0.0;  ///< In the position's units.
  /// Log decrement over the cycles in the fitted part (peaks of the same sign), for comparison.
  double zeta_log_decrement = 0.0;
  int cycles = 0;
  numerics::SolverSummary summary;
};

/// Analyses one record `position` (any length unit) sampled at `fs_hz`. InputError when no release
/// or fewer than two oscillation cycles are found, or when the fit gives zeta <= 0 (not a free
/// decay).
DecayResult AnalyzeDecay(const Eigen::Ref<const Eigen::VectorXd>& position, double fs_hz,
                         const DecayOptions& options);

struct AddedMassSolution {
  double k_n_per_m = 0.0;
  double base_mass_kg = 0.0;
};

/// Same spring, base mass m alone (omega_unloaded) and with `added_kg` (omega_loaded):
/// omega_u^2 = k/m, omega_l^2 = k/(m + added) => m = added omega_l^2/(omega_u^2 - omega_l^2),
/// k = m omega_u^2. InputError when omega_loaded >= omega_unloaded.
AddedMassSolution SolveAddedMass(double omega_unloaded_rad_s, double omega_loaded_rad_s,
                                 double added_kg);

}  // namespace vibid::ident
