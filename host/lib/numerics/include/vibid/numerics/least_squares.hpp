// Levenberg–Marquardt for the small dense nonlinear least-squares problems of the host: modal
// curve fits, mass updates, free-decay fits, prediction-error and output-error model searches.
// Problems have at most a few dozen parameters and some thousands of residuals.
//
// Cost F(x) = ½ ‖r(x)‖², as in Ceres. Each iteration factors J = QR once (Householder) and solves
// the damped step from the small system [R; √λ D] δ = −[Qᵀr; 0], with D the column norms of J
// (Marquardt's scaling, so parameters of very different size are treated alike). Solving through
// R instead of JᵀJ keeps the step accurate when J is ill conditioned.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>

namespace vibid::numerics {

/// Option names and meanings follow ceres::Solver::Options.
struct SolverOptions {
  int max_iterations = 200;
  /// An accepted step whose relative cost decrease (F_old − F_new) / F_old is at most this ends
  /// the search.
  double function_tolerance = 1e-12;
  /// A step with ‖δ‖ ≤ tol (‖x‖ + tol) ends the search.
  double parameter_tolerance = 1e-10;
  /// ‖Jᵀr‖∞ at most this ends the search.
  double gradient_tolerance = 1e-14;
  /// λ at the start, relative to the scaled Gauss–Newton matrix.
  double initial_damping = 1e-3;

  /// Throws InputError naming the first bad option.
  void Validate() const;
};

enum class TerminationType {
  kFunctionTolerance,   ///< Relative cost decrease below function_tolerance, or none possible.
  kParameterTolerance,  ///< Step below parameter_tolerance.
  kGradientTolerance,   ///< Gradient below gradient_tolerance.
  kMaxIterations,       ///< Stopped at max_iterations; the best parameters found are returned.
  kNumericalFailure,    ///< Non-finite residuals at the start, or no admissible step helps.
};

/// The option's name ("function_tolerance", "parameter_tolerance", "gradient_tolerance",
/// "max_iterations") or "numerical_failure"; the spelling every JSON output uses.
const char* TerminationName(TerminationType termination);

struct SolverSummary {
  TerminationType termination = TerminationType::kNumericalFailure;
  int iterations = 0;         ///< Iterations run (each one solves for at least one step).
  double initial_cost = 0.0;  ///< Cost at the start.
  double final_cost = 0.0;    ///< Cost at the returned parameters.
  std::string message;

  /// True for the three tolerance terminations: the result is a local minimum.
  bool Converged() const;
};

/// Fills `residuals` (length fixed by the first call) for `x` and, when `jacobian` is not null,
/// J = ∂r/∂x. Returns false when x is outside the model's domain (an unstable predictor, say); the
/// solver then treats the step as rejected and shortens it.
using ResidualFunction = std::function<bool(const Eigen::VectorXd& x, Eigen::VectorXd& residuals,
                                            Eigen::MatrixXd* jacobian)>;

/// A residual function without a Jacobian, for NumericDiff.
using ResidualOnlyFunction =
    std::function<bool(const Eigen::VectorXd& x, Eigen::VectorXd& residuals)>;

/// Wraps `residual` with a central-difference Jacobian, step `relative_step_size` × max(|x_j|, 1)
/// (as ceres::NumericDiffOptions). Central rather than forward differences: the modal fits are
/// judged at the 1e-4 level, where the O(h) error of forward differences on ill-scaled residuals
/// would show. Callers scale their parameters to O(1).
ResidualFunction NumericDiff(ResidualOnlyFunction residual, double relative_step_size = 1e-6);

/// What the solver holds at the point it returns, for a parameter covariance and residual analysis
/// without evaluating or factoring again.
struct Solution {
  Eigen::VectorXd residuals;  ///< r(x).
  Eigen::MatrixXd jacobian;   ///< J(x).
  Eigen::MatrixXd r_factor;   ///< R of J = QR: p × p upper triangular, RᵀR = JᵀJ.
};

/// Minimises ½ ‖r(x)‖² from `x` (updated in place with the best point found). `solution`, when
/// given, receives r, J and J's R factor at the returned x (all empty when the start itself could
/// not be evaluated). Numerical trouble is reported in the summary; only invalid options throw.
SolverSummary LevenbergMarquardt(const ResidualFunction& residual, Eigen::VectorXd& x,
                                 const SolverOptions& options, Solution* solution = nullptr);

/// Parameter covariance σ² (JᵀJ)⁻¹ with σ² = ‖r‖²/(N − p), by the SVD of J (pseudo-inverse on
/// rank deficiency, which gives infinite standard deviations for the unidentifiable directions).
Eigen::MatrixXd CovarianceFromJacobian(Eigen::Ref<const Eigen::MatrixXd> jacobian,
                                       Eigen::Ref<const Eigen::VectorXd> residual);

/// The same from J's R factor (J = QR): J and R have the same singular values and right singular
/// vectors, so only the p × p factor is decomposed.
Eigen::MatrixXd CovarianceFromFactor(Eigen::Ref<const Eigen::MatrixXd> r_factor,
                                     Eigen::Ref<const Eigen::VectorXd> residual);

}  // namespace vibid::numerics
