// Levenberg–Marquardt for the small nonlinear least-squares problems of identification (modal curve
// fit, mass update, free-decay fit). Problems have at most a few dozen parameters and a few thousand
// residuals, so a dense normal-equation step with a central-difference Jacobian is both simple and
// accurate enough; callers scale their parameters to O(1) (log masses, relative frequencies).
#pragma once

#include <functional>
#include <string>

#include <Eigen/Core>

namespace vibid::ident {

struct LmOptions {
  int max_iterations = 200;
  /// Stop when the relative cost decrease of an accepted step is below this.
  double function_tolerance = 1e-12;
  /// Stop when the step is below this relative to the parameter norm (+ this, absolute).
  double parameter_tolerance = 1e-10;
  /// Stop when the infinity norm of the gradient J^T r is below this.
  double gradient_tolerance = 1e-14;
  double initial_damping = 1e-3;
  /// Central-difference step relative to max(|p|, 1).
  double jacobian_step = 1e-6;

  /// InputError naming the first bad field.
  void Validate() const;
};

enum class Termination {
  kFunctionTolerance,
  kParameterTolerance,
  kGradientTolerance,
  kMaxIterations,
  kNumericalFailure,  ///< Non-finite residuals at the start, or no step could reduce the cost.
};

/// Short lowercase name ("function_tolerance", ...), used in JSON output.
const char* TerminationName(Termination termination);

struct SolverSummary {
  Termination termination = Termination::kNumericalFailure;
  int iterations = 0;
  double initial_cost = 0.0;  ///< 0.5 * |r|^2 at the start.
  double final_cost = 0.0;
  std::string message;

  /// True for the three tolerance terminations: the result is a local minimum.
  bool Converged() const;
};

/// Residual function: fills `residuals` (sized by the callee on first call, fixed afterwards) for
/// `params`. Returns false when the parameters are outside the model's domain; the solver then
/// treats the step as rejected.
using ResidualFunction = std::function<bool(const Eigen::VectorXd& params, Eigen::VectorXd& residuals)>;

/// Minimises 0.5 |r(p)|^2 starting from `params` (updated in place with the best point found).
SolverSummary LevenbergMarquardt(const ResidualFunction& residual, Eigen::VectorXd& params,
                                 const LmOptions& options);

}  // namespace vibid::ident
