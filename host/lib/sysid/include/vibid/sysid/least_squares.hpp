// Levenberg–Marquardt for nonlinear least squares with an analytic Jacobian, shared by the
// prediction-error, continuous-time output-error and grey-box estimators.
//
// Cost V(θ) = (1/N) Σ r_t(θ)². Each iteration factors J = QR once (Householder) and solves the
// damped step from the small system [R; √λ D] δ = −[Qᵀr; 0], D = column norms of J (Marquardt's
// scaling, so parameters of very different size are treated alike).
#pragma once

#include <functional>
#include <string>

#include <Eigen/Core>

namespace vibid::sysid {

enum class Termination {
  kConvergedCost,      ///< Relative cost decrease of an accepted step below cost_tolerance.
  kConvergedStep,      ///< Step below step_tolerance relative to the parameter size.
  kMaxIterations,      ///< Stopped at max_iterations; the last accepted parameters are returned.
  kNumericalFailure,   ///< Non-finite cost at the start, or no admissible step at any damping.
};

/// "converged-cost", "converged-step", "max-iterations", "numerical-failure".
const char* TerminationName(Termination t);

struct SolverOptions {
  int max_iterations = 200;
  double cost_tolerance = 1e-12;   ///< Relative decrease of V below which an accepted step ends the search.
  double step_tolerance = 1e-10;   ///< ‖δ‖ ≤ tol (‖θ‖ + tol) ends the search.
  double initial_damping = 1e-3;   ///< λ at the start, relative to the scaled Gauss–Newton matrix.
  /// Throws InputError naming the first bad option.
  void Validate() const;
};

struct SolverSummary {
  Termination termination = Termination::kNumericalFailure;
  int iterations = 0;          ///< Accepted or rejected Gauss–Newton/LM iterations run.
  double initial_cost = 0.0;   ///< V at the start.
  double final_cost = 0.0;     ///< V at the returned parameters.
  std::string message;

  bool Converged() const {
    return termination == Termination::kConvergedCost || termination == Termination::kConvergedStep;
  }
};

/// Residuals r(θ) (length N) and, when `jacobian` is not null, J = ∂r/∂θ (N × p). Returns false
/// when θ is not admissible (an unstable predictor, say); the solver then shortens the step.
using ResidualFunction =
    std::function<bool(const Eigen::VectorXd& theta, Eigen::VectorXd& residual, Eigen::MatrixXd* jacobian)>;

/// Minimises V from `theta` (updated in place). `jacobian_out`, when given, receives J at the
/// returned θ (for the parameter covariance).
SolverSummary MinimizeLeastSquares(const ResidualFunction& fn, Eigen::VectorXd& theta, const SolverOptions& options,
                                   Eigen::MatrixXd* jacobian_out = nullptr);

/// Parameter covariance σ² (JᵀJ)⁻¹ with σ² = ‖r‖²/(N − p), by the QR factor of J (pseudo-inverse on
/// rank deficiency, which gives infinite standard deviations for the unidentifiable directions).
Eigen::MatrixXd CovarianceFromJacobian(Eigen::Ref<const Eigen::MatrixXd> jacobian,
                                       Eigen::Ref<const Eigen::VectorXd> residual);

/// Instrumental-variable solution θ of Zᵀ Φ θ = Zᵀ y, with Φ's columns scaled to unit norm first
/// (regressors of y and u can differ by many orders of magnitude, which would otherwise look like
/// rank deficiency). Returns false when ZᵀΦ is singular or the solution is not finite.
bool SolveInstrumental(Eigen::Ref<const Eigen::MatrixXd> zeta, Eigen::Ref<const Eigen::MatrixXd> phi,
                       Eigen::Ref<const Eigen::VectorXd> target, Eigen::VectorXd& theta);

}  // namespace vibid::sysid
