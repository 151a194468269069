// Grey-box identification of the cart-track rig (methods §10): the physical parameters estimated
// directly by output error on the physical parameterisation.
//
// One cart (cart 2 pinned), springs k on both sides, viscous friction B:
//   force input     X1/F  = (1/M) / (s² + (B/M) s + 2k/M)
//   position input  X1/Xi = ((Bi/M) s + 2k/M) / (s² + (B/M) s + 2k/M)
// Two carts, output X1, det(s) = (M1 s² + B1 s + 2k)(M2 s² + B2 s + 2k) − k²:
//   force input     X1/F  = (M2 s² + B2 s + 2k) / det(s)
//   position input  X1/Xi = (Bi s + 2k)(M2 s² + B2 s + 2k) / det(s)
// (the position input acts through the first spring as F = (Bi s + 2k) Xi).
// With a position input the TF is homogeneous in (M, B, k, Bi) scale: one of them must be fixed.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "vibid/model/transfer_function.hpp"
#include "vibid/numerics/least_squares.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/fit.hpp"
#include "vibid/sysid/io_data.hpp"
#include "vibid/sysid/tfest.hpp"

namespace vibid::sysid {

using model::CartInput;

struct CartConfig {
  int carts = 1;  ///< 1 or 2.
  CartInput input = CartInput::kForce;
};

/// Parameter names in the order used by CartTf: 1 cart "M","B","k" (+ "Bi" for position input);
/// 2 carts "M1","M2","B1","B2","k" (+ "Bi").
std::vector<std::string> CartParameterNames(const CartConfig& config);

/// The cart TF (monic, the model core's CartTrackTf) for parameter values in CartParameterNames
/// order. SI units: M in kg, B and Bi in N·s/m, k in N/m.
TransferFunction CartTf(const CartConfig& config, Eigen::Ref<const Eigen::VectorXd> values);

struct GreyboxOptions {
  CartConfig config;
  std::map<std::string, double> fixed;  ///< Parameters held at a value (by name).
  InitialCondition ic = InitialCondition::kZero;
  numerics::SolverOptions solver;
  /// Throws InputError: unknown or non-positive fixed parameters, a position input without one
  /// fixed.
  void Validate() const;
};

struct GreyboxParameter {
  std::string name;
  double value = 0.0;
  /// 0 when fixed. When the residuals fail their tests, the larger of the white-residual value
  /// and the one for correlated residuals (correlated_covariance.hpp): see
  /// GreyboxResult::std_basis.
  double std = 0.0;
  double std_white = 0.0;  ///< sigma^2 (J^T J)^-1's, which holds for white residuals only.
  bool fixed = false;
};

struct GreyboxResult {
  std::vector<GreyboxParameter> parameters;
  TransferFunction tf;  ///< Monic, from the estimated parameters.
  double fit_percent = 0.0;
  std::string initialization;
  numerics::SolverSummary summary;
  /// The output error's residual tests (fewer than 101 samples: none, and the stds are white's).
  std::optional<ResidualTests> residual_tests;
  /// How the stds were made: "white residuals" or the correlated form with its lags.
  std::string std_basis = "white residuals";
};

GreyboxResult EstimateCart(const IoData& data, const GreyboxOptions& options);

}  // namespace vibid::sysid
