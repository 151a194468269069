// Modal parameters from measured FRFs: mode shapes from peak amplitudes (methods §5, Eq. 10) and a
// multi-mode least-squares curve fit of the modal FRF model started from the peak picks.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "vibid/ident/modal_model.hpp"
#include "vibid/ident/peaks.hpp"
#include "vibid/ident/spectral.hpp"
#include "vibid/ident/stabilization.hpp"
#include "vibid/numerics/least_squares.hpp"

namespace vibid::ident {

/// Whether a mode's damping depends on its amplitude, from the hits' ring-downs (ringdown.hpp).
struct AmplitudeDamping {
  bool checked = false;
  std::size_t hits = 0;  ///< Ring-downs the values come from.
  /// Apparent damping -d ln A / dt / omega over the first and the second half of the decay (in
  /// log amplitude), means over the hits.
  double zeta_early = 0.0;
  double zeta_late = 0.0;
  /// The envelope fit dA/dt = -zeta_v omega A - r: the viscous part, mean over the hits, with its
  /// 95 % interval from their scatter (Student t; NaN with fewer than 2 hits).
  double zeta_viscous = 0.0;
  std::array<double, 2> zeta_viscous_ci95{std::numeric_limits<double>::quiet_NaN(),
                                          std::numeric_limits<double>::quiet_NaN()};
  /// Modal friction force F_q (N, unit modal mass) and, with the same friction on every measured
  /// mass, that friction (N); NaN when not determined.
  double modal_friction_n = 0.0;
  std::array<double, 2> modal_friction_ci95{std::numeric_limits<double>::quiet_NaN(),
                                            std::numeric_limits<double>::quiet_NaN()};
  double friction_per_mass_n = 0.0;
  /// The friction rate's t statistic over the hits (its mean over its standard error; 0 with
  /// fewer than 2 hits), and the bias friction of that rate puts into an FRF's zeta, as a
  /// fraction of zeta: 2 b / a, b the envelope fit's friction offset (A = a exp(-sigma t) - b)
  /// and a its start, mean over the hits (an FRF weighs the decay by A^2, over which the
  /// apparent damping zeta + r / (omega A) averages to zeta (1 + 2 b / a)).
  double friction_rate_t = 0.0;
  double zeta_friction_bias = 0.0;
  /// The ring-downs reach their noise floor in less than half the time the mode's damping
  /// gives (in two thirds of the hits that reach it, two at least): dry friction stops them.
  /// stop_s and expected_stop_s are their means over those hits.
  bool stops_early = false;
  double stop_s = 0.0;
  double expected_stop_s = 0.0;
  /// The apparent damping grows as the amplitude falls beyond chance, or the ring-downs stop
  /// early: friction.
  bool amplitude_dependent = false;
  /// Not beyond chance, but the friction rate is positive and the bias it would put into the
  /// FRF's zeta reaches the FRF interval's half-width: the interval is widened down to the
  /// viscous part's (ApplyAmplitudeCheck).
  bool friction_hint = false;
  /// The envelope cannot be read (a component folded near it takes a smoothing longer than the
  /// decay allows, near the Nyquist limit): no friction rule applies; `note` says why.
  bool unavailable = false;
  std::string note;
};

/// One identified mode, in the same terms as a model's modal result.
struct ModeEstimate {
  double omega_rad_s = 0.0;
  double freq_hz = 0.0;
  double zeta = 0.0;
  /// Mass-normalised shape, one entry per response (phi^T M phi = 1 when the responses are the
  /// model's coordinates and the force is a unit force).
  Eigen::VectorXd shape;
  /// shape[0] / shape[1] for two responses (sign kept); NaN otherwise.
  double ratio = 0.0;
  /// 95 % confidence intervals [lo, hi] (lscf, lsce: from the modal model's covariance, see
  /// modal_model.hpp); NaN where a method gives none.
  std::array<double, 2> omega_ci95_rad_s{kNoInterval, kNoInterval};
  std::array<double, 2> zeta_ci95{kNoInterval, kNoInterval};
  std::array<double, 2> ratio_ci95{kNoInterval, kNoInterval};
  /// zeta_ci95 was widened past the method's own interval (friction suspected: down to the
  /// ring-downs' viscous part), so that it is no longer centred on zeta.
  bool zeta_ci95_widened = false;
  /// phi_j / phi_p for every response j, p the driving point (1 there), and their 95 % intervals
  /// (NaN where the method gives none; [1, 1] never: the driving point's entry has none). For two
  /// responses `ratio` is one of them or its inverse.
  Eigen::VectorXd shape_ratio;
  std::vector<std::array<double, 2>> shape_ratio_ci95;
  /// The estimate is known to be unreliable (`caution` says why and the way out): e.g. peak
  /// picking reached only because every better method failed on this FRF.
  bool unreliable = false;
  /// Why the mode is marked unreliable, or why an interval is withheld (empty when neither).
  std::string caution;
  /// The ring-down check of its damping (checked false when no time records were given).
  AmplitudeDamping amplitude;
  static constexpr double kNoInterval = std::numeric_limits<double>::quiet_NaN();
  bool HasIntervals() const {
    return std::isfinite(omega_ci95_rad_s[0]) && std::isfinite(zeta_ci95[0]);
  }
  /// Any interval at all (one may be withheld with a reason in `caution`).
  bool HasAnyInterval() const {
    bool any_shape = false;
    for (const auto& ci : shape_ratio_ci95) any_shape = any_shape || std::isfinite(ci[0]);
    return std::isfinite(omega_ci95_rad_s[0]) || std::isfinite(zeta_ci95[0]) ||
           std::isfinite(ratio_ci95[0]) || any_shape;
  }
};

/// Eq. 10 with the hammer at response `driving_point`: phi_p^2 = 2 zeta omega^2 |H_pp(omega)|,
/// phi_j phi_p = 2 zeta omega^2 |H_jp(omega)|, the sign of each product from whether H_jp is in
/// phase or in anti-phase with H_pp at the resonance. `receptance` must be a receptance.
std::vector<ModeEstimate> ShapesFromPeaks(const Frf& receptance, std::size_t driving_point,
                                          const std::vector<Peak>& peaks);

struct CurveFitOptions {
  /// Fitted band (Hz); 0 = automatic: from 0.6x the lowest to 1.4x the highest start frequency,
  /// within the data.
  double freq_min_hz = 0.0;
  double freq_max_hz = 0.0;
  /// Lower (mass-like, -1/(m omega^2)) and upper (constant flexibility) residual terms for the
  /// modes outside the band.
  bool residual_terms = true;
  /// Weight each line by its coherence (lines where the force had no energy count little).
  bool coherence_weighting = true;
  numerics::SolverOptions solver{
      .max_iterations = 100, .function_tolerance = 1e-12, .parameter_tolerance = 1e-12};

  void Validate() const;
};

struct FittedMode {
  double omega_rad_s = 0.0;
  double freq_hz = 0.0;
  double zeta = 0.0;
  Eigen::VectorXcd residues;  ///< One per response: H_j = sum_i A_ji / (omega_i^2 - omega^2 + 2j
                              ///< zeta_i omega_i omega).
};

struct CurveFitResult {
  std::vector<FittedMode> modes;
  Eigen::VectorXd lower_residual;  ///< Per response, coefficient of -1/omega^2.
  Eigen::VectorXd upper_residual;  ///< Per response, constant term.
  double freq_min_hz = 0.0;
  double freq_max_hz = 0.0;
  /// RMS of the weighted relative misfit |H_model - H| / |H| over the band.
  double rms_relative_error = 0.0;
  numerics::SolverSummary summary;
};

/// Fits all modes at once to a receptance (variable projection: the residues and residual terms
/// are solved linearly for each pole set, Levenberg–Marquardt moves the poles). InputError for a
/// non-receptance FRF or an empty start.
CurveFitResult FitModes(const Frf& receptance, const std::vector<Peak>& start,
                        const CurveFitOptions& options);

/// Residues (and residual terms) for given poles, by linear least squares over the band
/// (least-squares frequency domain, "LSFD"): the same model and weights as FitModes with the
/// poles held. `zeta` is the damping the FRF shows (before any exponential-window correction).
/// The summary reports a converged linear solve.
CurveFitResult FitResidues(const Frf& receptance, const std::vector<double>& omega_rad_s,
                           const std::vector<double>& zeta, const CurveFitOptions& options);

/// Mass-normalised shapes from fitted residues (A_jp = phi_j phi_p), hammer at `driving_point`;
/// the sign of phi_j from the real part of A_jp relative to A_pp.
std::vector<ModeEstimate> ShapesFromResidues(const CurveFitResult& fit, std::size_t driving_point);

enum class ModeMethod { kPeakPicking, kCurveFit, kLscf, kLsce };
/// "peaks" | "fit" | "lscf" | "lsce"; InputError otherwise.
ModeMethod ParseModeMethod(std::string_view name);

struct ModeIdentificationOptions {
  ModeMethod method = ModeMethod::kLscf;
  PeakOptions peaks;
  /// Column whose magnitude is peak-picked; -1: the sum of all responses' magnitudes.
  int picking_column = -1;
  CurveFitOptions fit;
  /// lscf/lsce: orders and stability criteria (the band is the peak options' band).
  StabilizationOptions stabilization;
  /// lscf with no stable pole falls back to lsce, then to the curve fit, with a warning; true
  /// turns that off (an InputError instead).
  bool stabilization_fallback_off = false;
};

/// A clear peak no mode explains whose ring-down (read where the identified shapes leave room)
/// shows a damping that grows as the amplitude falls: dry friction, the likely cause of the lost
/// mode.
struct FrictionAtLostPeak {
  double freq_hz = 0.0;
  double zeta_early = 0.0;  ///< Apparent damping over the ring-downs' early part.
  double zeta_late = 0.0;   ///< And over their late part.
  std::size_t hits = 0;     ///< Ring-downs read.
  /// The ring-downs die before the peak's half-power damping would let them (zeta_early and
  /// zeta_late then unread): stop_s against expected_stop_s, means over the hits.
  bool stops_early = false;
  double stop_s = 0.0;
  double expected_stop_s = 0.0;
};

struct ModeIdentification {
  std::vector<ModeEstimate> modes;
  std::vector<Peak> peaks;
  std::vector<std::string> warnings;
  bool fitted = false;
  CurveFitResult
      fit;  ///< Valid when `fitted` (for lscf/lsce: the residue fit with the chosen poles).
  bool has_diagram = false;
  StabilizationDiagram diagram;  ///< lscf/lsce.
  /// Modes that were estimated but are not reported: damping not resolved (zeta <= 1e-6, or its
  /// interval reaches 0).
  std::vector<ModeEstimate> dropped;
  /// Clear resonance peaks of the band (see IdentifyModes) that no reported or dropped mode
  /// explains, in Hz; each also has a warning naming the way out.
  std::vector<double> peaks_without_mode_hz;
  /// Their half-power damping, in the same order (Peak::zeta; a peak narrower than its lines reads
  /// wider than it is, so this errs high): what the ring-down check of a lost peak expects.
  std::vector<double> peaks_without_mode_zeta;
  /// Those of them whose ring-downs show dry friction (the ring-down check, CheckRingDowns).
  std::vector<FrictionAtLostPeak> friction_at_lost_peaks;
  /// lscf/lsce: the modal model refined from the chosen poles, which gives the reported omega,
  /// zeta, shape directions and their intervals (valid when `has_model`).
  bool has_model = false;
  ModalModelFit model;
};

/// Peak picks (and, by default, the curve fit started from them) on a receptance, or the poles a
/// stabilization diagram chooses (lscf/lsce) with residues fitted for them; shapes with the
/// hammer at `driving_point`. A mode whose damping is not resolved (zeta <= 1e-6, or a 95 %
/// interval on zeta that reaches 0) is never reported as a mode: it is moved to `dropped` with a
/// warning. A clear peak of the band (a resonance the peak picker finds, at least 5 % of the
/// largest, whose half-power band spans 2 lines or more) that no mode explains is named in
/// `peaks_without_mode_hz` and a warning with the way out (orders, band, method). InputError when
/// no resonance is found. A curve fit that does not converge is reported in `fit.summary`, and the
/// peak-pick modes are returned with a warning.
ModeIdentification IdentifyModes(const Frf& receptance, std::size_t driving_point,
                                 const ModeIdentificationOptions& options);

/// Receptance of a modal model at `omega_rad_s` (for overlays and tests).
Eigen::VectorXcd ModalReceptance(const CurveFitResult& fit, double omega_rad_s);

}  // namespace vibid::ident
