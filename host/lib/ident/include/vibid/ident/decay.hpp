// Free-decay analysis of pull-and-release records (no force channel): find the release, fit a
// damped sinusoid over the whole decay, and from a loaded/unloaded pair of the same spring solve
// for the stiffness and the base mass.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

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

/// Friction read from the half cycles (the peaks between crossings, from the release down to the
/// end fraction of the first): a viscous decay loses a fixed fraction of its amplitude every half
/// cycle, Coulomb friction a fixed amount: each half cycle runs from rest to rest about a centre
/// shifted by F / k against the motion, so the peaks follow A_{k+1} = rho A_k - d, with
/// rho = exp(-pi zeta_v / sqrt(1 - zeta_v^2)) from the viscous part and d = (1 + rho) F / k. Under
/// friction the damping a half cycle shows grows as the amplitude falls, and a purely viscous fit's
/// zeta is an average over the amplitudes it spans.
struct DecayFriction {
  bool checked = false;
  std::string note;     ///< Why not checked, when not.
  int half_cycles = 0;  ///< Peak pairs in the regression.
  /// Apparent damping per half cycle (from ln(A_k / A_{k+1})), the mean over the first and the
  /// last third of the half cycles.
  double zeta_first = 0.0;
  double zeta_last = 0.0;
  /// Viscous part from rho (NaN when rho >= 1: no viscous part resolved beside the friction).
  double zeta_viscous = 0.0;
  /// Coulomb loss per half cycle d (position units) and its 95 % half-width; F / k = d / (1 + rho).
  double drop_per_half_cycle = 0.0;
  double drop_ci95 = 0.0;
  double friction_over_k = 0.0;  ///< F / k (position units).
  /// Angular frequency from the crossings of the first and of the last two cycles.
  double omega_first_rad_s = 0.0;
  double omega_last_rad_s = 0.0;
  /// Friction detected: d > 0 beyond its 95 % interval and the late half cycles' damping at
  /// least `kFrictionGrowth` times the early ones'.
  bool detected = false;
};

inline constexpr double kFrictionGrowth = 1.15;
/// The fit's and the log decrement's zeta are stated as disagreeing beyond this relative gap.
inline constexpr double kDampingEstimatesGap = 0.15;

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
  DecayFriction friction;
  /// Plain-language cautions: friction named, the two damping estimates disagreeing. Empty when
  /// the decay reads as viscous.
  std::vector<std::string> cautions;
};

/// Analyses one record `position` (any length unit, either sign: the result's frequencies,
/// damping and cautions do not depend on the position's sign or unit) sampled at `fs_hz`.
/// InputError when no release or fewer than two oscillation cycles are found, or when the fit gives
/// zeta <= 0 (not a free decay).
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
