// The identification chain (methods §6-8): effective masses from 1-DOF hammer tests, modes from
// 2-DOF hammer tests, stiffness (and damping) from the modes with the updated masses, averaged
// over tests, an updated chain model and the validation table against the nominal model.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/common/verdict.hpp"
#include "vibid/ident/chain_fit.hpp"
#include "vibid/ident/intervals.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/ringdown.hpp"
#include "vibid/ident/spectral.hpp"
#include "vibid/ident/updates.hpp"
#include "vibid/model/model.hpp"

namespace vibid::ident {

/// Chain parameters of a model by the diagonal convention (k_n = K_nn, k_i = K_ii - k_{i+1}; the
/// same for C); masses from the diagonal of M.
struct ChainParameters {
  Eigen::VectorXd masses_kg;
  Eigen::VectorXd springs_n_per_m;
  Eigen::VectorXd dampers_ns_per_m;
};
ChainParameters ChainOf(const model::Model& model);

/// One row per mode: the nominal model, the updated model and the test side by side.
struct ModeComparison {
  std::size_t mode = 0;  ///< The models' mode (0-based, ascending frequency) the test mode is.
  double omega_nominal = 0.0, omega_updated = 0.0, omega_test = 0.0;
  double zeta_nominal = 0.0, zeta_updated = 0.0, zeta_test = 0.0;
  double ratio_nominal = 0.0, ratio_updated = 0.0, ratio_test = 0.0;
  /// Shapes scaled to 1 at the driving point, one entry per response (empty when the test's
  /// responses are not the models' coordinates).
  Eigen::VectorXd shape_nominal, shape_updated, shape_test;
};

struct PositionComparison {
  double m_nominal = 0.0, m_updated = 0.0;
  double k_nominal = 0.0, k_updated = 0.0;
  double c_updated = 0.0;
  /// 95 % intervals of the updated values, or why there are none (Identify fills them).
  Interval95 m_ci95, k_ci95, c_ci95;
  /// The one-test chain fit: where each value came from ("test", "test and prior", "prior");
  /// empty for the mass-test method.
  std::string m_source, k_source, c_source;
};

/// How far a model's modes are from the test's: the root mean square over the test's modes of
/// sqrt(dev_omega^2 + dev_shape^2) in %, dev_shape = |phi_model - phi_test| / |phi_test| with
/// both shapes scaled to 1 at the driving point. Damping is left out: a nominal model's damping
/// is seldom more than a guess, and counting it would let an update that moves the frequencies
/// and shapes away from the test pass as better.
struct ModalDeviation {
  double nominal_percent = 0.0;
  double updated_percent = 0.0;
  /// The update fits its own test worse than the nominal model does.
  bool worse_than_nominal = false;
};

struct ValidationTable {
  /// "one-test chain fit" or "mass tests": how the updated values were found.
  std::string method;
  std::vector<ModeComparison> modes;
  std::vector<PositionComparison> positions;
  ModalDeviation deviation;
  /// The other method's values beside (the one-test chain fit when mass tests are given), its
  /// name and its modal deviation (updated_percent); empty when there is none.
  std::string beside_method;
  std::vector<PositionComparison> beside;
  ModalDeviation beside_deviation;
  /// Why the updated values are not to be trusted although no check refused them (the one-test
  /// fit without intervals, say); empty when there is nothing to say.
  std::string caution;
};

/// 100 (value - reference) / reference.
double PercentDeviation(double value, double reference);

/// Modal analysis of both models (model core) against the test modes, mode by mode in frequency
/// order (test mode i is the models' mode `chain_modes[i]`; empty: mode i); positions from the
/// chain parameters; the modal deviation of both models with the hammer at `driving_point`.
ValidationTable BuildValidationTable(const model::Model& nominal, const model::Model& updated,
                                     const std::vector<ModeEstimate>& test_modes,
                                     const std::vector<Eigen::Index>& chain_modes = {},
                                     std::size_t driving_point = 1);

/// ModalDeviation of `model` from the test modes (see there).
double ModalDeviationPercent(const model::Model& model, const std::vector<ModeEstimate>& test_modes,
                             const std::vector<Eigen::Index>& chain_modes,
                             std::size_t driving_point);

/// Fixed-width text table (the % columns are deviations from the test / changes from nominal;
/// positions with their 95 % intervals as +- half-width, or n/a and the reason).
std::string FormatValidationTable(const ValidationTable& table);

struct MassTestInput {
  std::size_t position = 0;  ///< 0-based mass index.
  Frf receptance;            ///< One response: the mass alone on its spring.
  double k_n_per_m = 0.0;  ///< Spring of the 1-DOF test; 0: the nominal chain spring of `position`.
  bool fit_spring = false;  ///< The spring is not known: fit it with the mass (k_n_per_m ignored).
};

struct IdentifyOptions {
  std::size_t driving_point = 1;  ///< Response column of the modal tests at the hammer.
  ModeIdentificationOptions modes;
  MassUpdateOptions mass;  ///< k and nominal are filled per test.
  /// The one-test chain fit (its driving point is set from `driving_point`).
  ChainFitOptions chain;
  /// The used hits' ring-downs of each modal test (RingDownsOf), in the tests' order, or empty.
  /// Given, each test's modes take the amplitude check as `vibid modes` does (ringdown.hpp): a
  /// mode whose damping grows as the ring-down dies (friction) keeps the viscous part, and its
  /// damping interval (with the dampers') is withheld when the ring-downs cannot give one.
  /// A test whose ring-downs hold no hit, or other responses than its FRF, is left unchecked.
  std::vector<RingDowns> modal_ringdowns;
};

struct MassTestResult {
  std::size_t position = 0;
  MassUpdateResult update;
};

/// The positions' uncertainties (see Identify).
struct PositionUncertainty {
  Uncertainty m_kg, k_n_per_m, c_ns_per_m;
};

struct IdentifyResult {
  /// "one-test chain fit" (no mass tests) or "mass tests".
  std::string method;
  model::Model updated;
  ChainParameters chain;
  std::vector<MassTestResult> mass_tests;
  std::vector<ModeIdentification> modal_tests;
  /// Averaged over the modal tests; 95 % intervals of the mean from the tests' intervals, or from
  /// their scatter when they disagree beyond them (MeanOfRepeats, intervals.hpp).
  std::vector<ModeEstimate> test_modes;
  StiffnessAverage stiffness;
  /// One per position: m from its mass tests (fit covariance; several tests of one position
  /// combine as repeats), k and c from the update map's Jacobian applied to the modes' intervals
  /// (omega, zeta, a1/a2) and the masses' uncertainties, the modal tests combined as repeats
  /// (intervals.hpp). The table's intervals are made of these.
  std::vector<PositionUncertainty> uncertainty;
  ValidationTable table;
  /// The one-test chain fit (methods §12): the result without mass tests, beside the mass-test
  /// method's when both can be made; `has_chain_fit` false when it could not (a warning says why).
  bool has_chain_fit = false;
  ChainFitResult chain_fit;
  /// Test mode i is chain mode `chain_modes[i]` (fewer modes than masses: the prior fills in).
  std::vector<Eigen::Index> chain_modes;
  std::vector<std::string> warnings;
  /// How far the result is to be trusted, decided here for every front end: flagged
  /// ("worse_than_nominal") when the update fits its own test worse than the nominal model,
  /// caution ("chain_fit_unchecked") when the one-test fit has no intervals to check it by.
  Verdict verdict;
};

/// Runs the chain. Without mass tests the masses, springs and dampers are fitted to the modal
/// tests' modes (FitChain: the driving-point residues scale the shapes to unit modal mass, and
/// the chain's parameters are fitted to omega, zeta and the shapes with the modal covariances as
/// weights; a test with fewer modes than masses takes the nominal model as a prior). With mass
/// tests the masses come from them and the springs and dampers from the modes (methods §6-7), and
/// the chain fit is shown beside. An update that fits its own test worse than the nominal model
/// is flagged (ModalDeviation, a warning, the verdict). Several mass tests of one position are
/// repeats: their masses are averaged. InputError on inconsistent inputs (mode counts, positions,
/// non-receptances); a mass fit that fails to converge or an updated model that is not physical is
/// reported by InputError naming the test, since no model can be produced from it.
IdentifyResult Identify(const model::Model& nominal, const std::vector<MassTestInput>& mass_tests,
                        const std::vector<Frf>& modal_tests, const IdentifyOptions& options);

}  // namespace vibid::ident
