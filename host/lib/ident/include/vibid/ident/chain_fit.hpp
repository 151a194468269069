// Physical parameters of a chain from one hammer test of the assembled rig (methods §12): the
// unit-modal-mass shapes that the driving-point residues give (A_r = phi_r phi_r^T, phi_pr =
// sqrt(A_ppr), phi_jr = A_jpr / phi_pr), then the chain's masses, springs and dampers
// (m_i, k_i, c_i > 0) fitted to the modal data (omega, zeta, shapes) by weighted least squares
// with the modal covariances as weights (Ewins, Modal Testing, 2nd ed., §6; Friswell &
// Mottershead, Finite Element Model Updating in Structural Dynamics, ch. 6).
//
// Why a fit and not the closed forms M^-1 = Phi Phi^T, K = M Phi Omega^2 Phi^T M: with noise those
// give off-chain terms (a mass matrix that is not diagonal, springs between masses that are not
// connected), and they need every mode in the band. The fit stays on the chain's topology, weighs
// each datum by what the test knows of it, and takes any number of modes: where the test has
// fewer modes than masses, the nominal model enters as a prior (each parameter log-normal about its
// nominal value with a stated relative spread), and the posterior-to-prior variance ratio of each
// parameter says whether the test or the prior determined it.
//
// The model side is the same map from residues to shapes as the data side: the damped chain's
// poles and receptance residues (the state matrix's eigenvectors, any damping), A_jp = residue of
// x_j / F_p, q_j = 2 j omega_d A_jp, phi_p = sqrt(|q_p|), phi_j = Re(q_j conj(q_p)) / |q_p| /
// phi_p. For a real (proportionally damped) mode this is the unit-modal-mass shape exactly; for a
// complex one both sides take the same real projection, so non-proportional damping does not bias
// the fit.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "vibid/ident/intervals.hpp"
#include "vibid/ident/modal_model.hpp"
#include "vibid/model/model.hpp"
#include "vibid/numerics/least_squares.hpp"

namespace vibid::ident {

/// One identified mode as the chain fit uses it: y = [omega, zeta, phi_1 .. phi_n] with phi the
/// unit-modal-mass shape (response j measures mass j; phi at the driving point > 0).
struct ChainModeData {
  Eigen::VectorXd values;
  /// Covariance of `values`; empty when the test gives none (then no interval can follow).
  Eigen::MatrixXd covariance;
  /// Why there is no covariance (empty when there is one).
  std::string no_covariance;
  /// Relative variance of the FRF's level at this mode's line from the noise on the force inside
  /// the force windows (Frf::level_rel_var): it scales every residue of the mode alike, so the
  /// modal model's residuals do not show it; FitChain adds it to the shape's covariance. The
  /// noise of a force window of W samples is correlated over about fs / W in frequency, less
  /// than the spacing of a chain's modes, so the modes' level errors are taken as independent.
  double level_rel_var = 0.0;
  /// Why the test's zeta of this mode carries no interval (friction, say): zeta then weighs
  /// nothing in the fit, and the dampers get no interval, with this reason. Empty: it has one.
  std::string zeta_withheld;
  /// Relative standard deviation of the mode's shape entries and zeta from what the record's
  /// windows leave of the previous hits' ringing and cut of this one's (identify sets it from the
  /// ringing left at the record's end, ChainFitOptions::ringing_error_per_left); no noise term
  /// holds it, and it does not shrink with more hits of the same spacing.
  double ringing_rel_sd = 0.0;
};

/// omega, zeta and unit-modal-mass shape of `mode` of a modal model fit (the hammer at response
/// `driving_point`), with their joint covariance through the fit's covariance (the pole and the
/// residues of that mode). The residues are the accelerance ones of the structure's pole
/// (window-corrected): phi_j phi_p = Re(2 j omega_d R_j / lambda^2) in the projection above.
/// InputError when the driving-point residue does not give a positive phi_p^2.
ChainModeData ChainDataOfMode(const ModalModelFit& fit, Eigen::Index mode,
                              Eigen::Index driving_point);

/// The same quantities of a chain model (its modes in ascending frequency), for the fit and tests.
/// InputError when the chain has a mode that does not oscillate.
std::vector<Eigen::VectorXd> ChainModalQuantities(const model::Model& chain,
                                                  Eigen::Index driving_point);

struct ChainFitOptions {
  Eigen::Index driving_point = 0;
  /// Relative spread (standard deviation of the log) of the nominal model as a prior; used only
  /// when the tests show fewer modes than masses. A damper the nominal model does not give
  /// (0) takes its start value with a spread of a factor e.
  double prior_relative_sd = 0.2;
  /// A parameter whose posterior variance is below this fraction of its prior variance was
  /// determined by the test; above `prior_ratio_from_prior` it came from the prior.
  double prior_ratio_determined = 0.1;
  double prior_ratio_from_prior = 0.9;
  /// The covariance is widened by chi2 / dof when the chain explains the data worse than their
  /// covariances say; beyond this factor (in variance) no interval is given.
  double max_covariance_scale = 10.0;
  /// Identify withholds the fit's intervals when a mode still holds more than this fraction of
  /// its amplitude at the record's end, exp(-zeta omega (record - pretrigger)) with the
  /// exponential window's decay added: there the modal model cannot tell the hit's own response
  /// from the ringing the records hold, and the residues (the masses' scale) stray far beyond
  /// their covariance (chain_fit_coverage_test: hits 5-5.5 s apart, 19 % left of mode 1, estimates
  /// 15-50 % apart; 8-9 s apart, 7 % left, the intervals hold).
  double max_ringing_left = 0.1;
  /// The method's own error, which no noise term holds: the modal model's residues and poles off
  /// by a part that does not shrink with the noise (relative standard deviations of omega, zeta
  /// and each shape entry, the last relative to the shape's largest entry). Added to every mode's
  /// covariance, so the chi-square test passes a true chain at its stated rate and no interval is
  /// narrower than the method's systematic error. Measured with an independent simulator at 0.01 %
  /// noise (benchmarks/coverage/chain_coverage.py --noise 0.0001; docs/identification.md): the
  /// shapes of the higher modes of 3 and 4 masses off by up to 13 of their noise's standard
  /// deviations, about 0.1 % of the largest entry, with every hit fully rung down (3 hits 40 s
  /// apart); 0.2 % holds them.
  double systematic_omega_rel = 0.0;
  double systematic_zeta_rel = 0.0;
  double systematic_shape_rel = 0.002;
  /// The relative error of a mode's shape and zeta per unit of its amplitude left at the record's
  /// end (ChainModeData::ringing_rel_sd = this times exp(-zeta omega (record - pretrigger))): the
  /// previous hit's ringing in a record, which the hits' spacing and heights set. Same study: a
  /// 2-mass chain's mode 1 keeping 1.4 % after 8-9 s moved every m, k and c by -0.7 to +0.8 % at
  /// 0.01 % noise (chi-square 184 to 2490 with 2 dof); 1 holds them.
  double ringing_error_per_left = 1.0;
  numerics::SolverOptions solver{
      .max_iterations = 200, .function_tolerance = 1e-14, .parameter_tolerance = 1e-12};

  void Validate() const;
};

/// The modes of one test with the chain mode (0-based, ascending frequency) each one is.
struct ChainTestModes {
  std::vector<ChainModeData> modes;
  std::vector<Eigen::Index> chain_mode;
};

/// Where a parameter's value came from.
enum class ParameterSource { kTest, kTestAndPrior, kPrior };
const char* ParameterSourceName(ParameterSource source);

struct ChainFitResult {
  Eigen::VectorXd masses_kg, springs_n_per_m, dampers_ns_per_m;
  /// 95 % intervals' uncertainties, one per position (see FitChain).
  std::vector<Uncertainty> m_u, k_u, c_u;
  /// Only with the prior: posterior-to-prior variance ratio per parameter, order m, k, c (each
  /// n long); empty without it.
  Eigen::VectorXd prior_variance_ratio;
  /// Per parameter (m, k, c order): the test, both, or the prior (kTest without the prior).
  std::vector<ParameterSource> source;
  bool prior_used = false;
  /// Chain modes the tests showed (0-based).
  std::vector<Eigen::Index> modes_seen;
  /// Weighted misfit (without the prior's terms) and its degrees of freedom (data - parameters).
  double chi2 = 0.0;
  int dof = 0;
  /// chi2 / dof when it exceeds 1 and the covariance was scaled by it, else 1.
  double covariance_scale = 1.0;
  numerics::SolverSummary summary;
  std::vector<std::string> warnings;
};

/// Weighted least squares of the chain's log parameters to the tests' modal data, started from the
/// nominal model and, with every mode seen, from the closed forms as well (the better of the two
/// kept). The modes of every test are independent data. The parameters' covariance is (J^T W J)^-1
/// at the minimum, scaled by chi2 / dof when the chain explains the data worse than their
/// covariances say (a warning names it; beyond max_covariance_scale no interval); each interval is
/// value +- 1.96 sd on that covariance (delta method from the log). No interval when a mode has no
/// covariance (the reason is given). InputError on sizes (modes, shapes), a chain mode seen twice
/// in one test, or no mode at all.
ChainFitResult FitChain(const model::Model& nominal, const std::vector<ChainTestModes>& tests,
                        const ChainFitOptions& options);

/// Assigns identified modes (ascending omega) to the chain's modes: the order-preserving choice
/// closest in log frequency to the nominal model's. InputError for more modes than the chain has.
std::vector<Eigen::Index> MatchChainModes(const model::Model& nominal,
                                          const std::vector<double>& omega_rad_s);

}  // namespace vibid::ident
