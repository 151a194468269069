// The identification chain (methods §6-8): effective masses from 1-DOF hammer tests, modes from
// 2-DOF hammer tests, stiffness (and damping) from the modes with the updated masses, averaged
// over tests, an updated chain model and the validation table against the nominal model.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/ident/intervals.hpp"
#include "vibid/ident/modes.hpp"
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
  double omega_nominal = 0.0, omega_updated = 0.0, omega_test = 0.0;
  double zeta_nominal = 0.0, zeta_updated = 0.0, zeta_test = 0.0;
  double ratio_nominal = 0.0, ratio_updated = 0.0, ratio_test = 0.0;
};

struct PositionComparison {
  double m_nominal = 0.0, m_updated = 0.0;
  double k_nominal = 0.0, k_updated = 0.0;
  double c_updated = 0.0;
  /// 95 % intervals of the updated values, or why there are none (Identify fills them).
  Interval95 m_ci95, k_ci95, c_ci95;
};

struct ValidationTable {
  std::vector<ModeComparison> modes;
  std::vector<PositionComparison> positions;
};

/// 100 (value - reference) / reference.
double PercentDeviation(double value, double reference);

/// Modal analysis of both models (model core) against the test modes, mode by mode in frequency
/// order; positions from the chain parameters.
ValidationTable BuildValidationTable(const model::Model& nominal, const model::Model& updated,
                                     const std::vector<ModeEstimate>& test_modes);

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
  std::vector<std::string> warnings;
};

/// Runs the chain. Several mass tests of one position are repeats: their masses are averaged.
/// InputError on inconsistent inputs (mode counts, positions, non-receptances);
/// a mass fit that fails to converge or an updated model that is not physical is reported by
/// InputError naming the test, since no model can be produced from it.
IdentifyResult Identify(const model::Model& nominal, const std::vector<MassTestInput>& mass_tests,
                        const std::vector<Frf>& modal_tests, const IdentifyOptions& options);

}  // namespace vibid::ident
