#include "vibid/numerics/least_squares.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "vibid/common/error.hpp"

namespace vibid::numerics {

void SolverOptions::Validate() const {
  Require(max_iterations >= 1, "solver: max_iterations must be at least 1");
  Require(std::isfinite(function_tolerance) && function_tolerance >= 0.0,
          "solver: function_tolerance must be >= 0");
  Require(std::isfinite(parameter_tolerance) && parameter_tolerance >= 0.0,
          "solver: parameter_tolerance must be >= 0");
  Require(std::isfinite(gradient_tolerance) && gradient_tolerance >= 0.0,
          "solver: gradient_tolerance must be >= 0");
  Require(std::isfinite(initial_damping) && initial_damping > 0.0,
          "solver: initial_damping must be > 0");
}

const char* TerminationName(TerminationType termination) {
  switch (termination) {
    case TerminationType::kFunctionTolerance: return "function_tolerance";
    case TerminationType::kParameterTolerance: return "parameter_tolerance";
    case TerminationType::kGradientTolerance: return "gradient_tolerance";
    case TerminationType::kMaxIterations: return "max_iterations";
    case TerminationType::kNumericalFailure: return "numerical_failure";
  }
  return "numerical_failure";
}

bool SolverSummary::Converged() const {
  return termination == TerminationType::kFunctionTolerance ||
         termination == TerminationType::kParameterTolerance ||
         termination == TerminationType::kGradientTolerance;
}

ResidualFunction NumericDiff(ResidualOnlyFunction residual, double relative_step_size) {
  Require(std::isfinite(relative_step_size) && relative_step_size > 0.0 && relative_step_size < 0.1,
          "solver: relative_step_size must be in (0, 0.1)");
  return [f = std::move(residual), relative_step_size](const Eigen::VectorXd& x, Eigen::VectorXd& r,
                                                       Eigen::MatrixXd* jacobian) {
    if (!f(x, r)) return false;
    if (jacobian == nullptr) return true;
    jacobian->resize(r.size(), x.size());
    Eigen::VectorXd probe = x;
    Eigen::VectorXd r_plus(r.size());
    Eigen::VectorXd r_minus(r.size());
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      const double h = relative_step_size * std::max(std::abs(x[j]), 1.0);
      probe[j] = x[j] + h;
      if (!f(probe, r_plus) || !r_plus.allFinite()) return false;
      probe[j] = x[j] - h;
      if (!f(probe, r_minus) || !r_minus.allFinite()) return false;
      probe[j] = x[j];
      jacobian->col(j) = (r_plus - r_minus) / (2.0 * h);
    }
    return true;
  };
}

namespace {

// The state of one minimisation: the current point with its residuals and Jacobian.
struct Point {
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  double cost = 0.0;
};

bool EvaluateResiduals(const ResidualFunction& f, const Eigen::VectorXd& x, Eigen::VectorXd& r,
                       double& cost) {
  if (!f(x, r, nullptr) || !r.allFinite()) return false;
  cost = 0.5 * r.squaredNorm();
  return true;
}

bool EvaluateWithJacobian(const ResidualFunction& f, const Eigen::VectorXd& x, Point& point) {
  if (!f(x, point.r, &point.jac) || !point.r.allFinite() || !point.jac.allFinite()) return false;
  point.cost = 0.5 * point.r.squaredNorm();
  return true;
}

// Marquardt's scaling: column norms of J, floored so that a parameter the residuals ignore still
// gets a damped (finite) step.
Eigen::VectorXd ColumnScale(const Eigen::MatrixXd& jac) {
  Eigen::VectorXd scale = jac.colwise().norm().transpose();
  const double largest = scale.size() > 0 ? scale.maxCoeff() : 0.0;
  const double floor = largest > 0.0 ? 1e-6 * largest : 1.0;
  for (Eigen::Index j = 0; j < scale.size(); ++j) {
    if (!(scale[j] > floor)) scale[j] = floor;
  }
  return scale;
}

// The small triangular system of one iteration: J = QR, so ‖J δ + r‖ = ‖R δ + Qᵀ r‖ up to a
// constant and every damping tried costs only a 2p × p solve.
struct Factored {
  Eigen::MatrixXd rfac;
  Eigen::VectorXd qtr;
  Eigen::VectorXd scale;
};

/// R of J = QR as a p × p upper triangle (zero rows below J's row count when J is wide).
Eigen::MatrixXd UpperFactor(const Eigen::HouseholderQR<Eigen::MatrixXd>& qr) {
  const Eigen::Index p = qr.matrixQR().cols();
  const Eigen::Index rows = std::min(p, qr.matrixQR().rows());
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(p, p);
  r.topRows(rows) = qr.matrixQR().topRows(rows).triangularView<Eigen::Upper>();
  return r;
}

Factored Factor(const Point& point) {
  const Eigen::Index p = point.jac.cols();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(point.jac);
  Factored out;
  const Eigen::Index rows = std::min(p, point.jac.rows());
  out.rfac = UpperFactor(qr);
  out.qtr = Eigen::VectorXd::Zero(p);
  out.qtr.head(rows) = (qr.householderQ().transpose() * point.r).head(rows);
  out.scale = ColumnScale(point.jac);
  return out;
}

Eigen::VectorXd DampedStep(const Factored& f, double lambda) {
  const Eigen::Index p = f.rfac.cols();
  Eigen::MatrixXd aug(2 * p, p);
  aug.topRows(p) = f.rfac;
  aug.bottomRows(p) = (std::sqrt(lambda) * f.scale).asDiagonal();
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * p);
  rhs.head(p) = -f.qtr;
  return aug.householderQr().solve(rhs);
}

bool StepIsNegligible(const Eigen::VectorXd& step, const Eigen::VectorXd& x, double tolerance) {
  return step.norm() <= tolerance * (x.norm() + tolerance);
}

// When no damping gives a decrease, the point is a minimum to working precision if the scaled
// gradient relative to the residual vanishes; otherwise the model cannot move.
void FinishWithoutStep(const Point& point, const Eigen::VectorXd& scale, SolverSummary& summary) {
  const double gradient = (point.jac.transpose() * point.r).cwiseQuotient(scale).norm() /
                          std::max(point.r.norm(), 1e-300);
  if (gradient < 1e-6) {
    summary.termination = TerminationType::kFunctionTolerance;
    summary.message = "no further decrease possible: at a minimum to working precision";
  } else {
    summary.termination = TerminationType::kNumericalFailure;
    summary.message = "no admissible step lowers the cost";
  }
}

}  // namespace

SolverSummary LevenbergMarquardt(const ResidualFunction& residual, Eigen::VectorXd& x,
                                 const SolverOptions& options, Solution* solution) {
  options.Validate();
  SolverSummary summary;
  Point point;
  if (!EvaluateWithJacobian(residual, x, point)) {
    summary.message = "residuals or Jacobian not finite at the starting point";
    return summary;
  }
  summary.initial_cost = point.cost;
  // Above this the step is nothing: the damping has swamped the Gauss–Newton matrix.
  constexpr double kMaxDamping = 1e16;
  double lambda = options.initial_damping;
  Eigen::VectorXd trial_r;
  Factored factored;
  bool factored_here = false;  // `factored` is that of `point`
  bool done = false;
  while (!done) {
    if (summary.iterations >= options.max_iterations) {
      summary.termination = TerminationType::kMaxIterations;
      summary.message = "stopped after " + std::to_string(summary.iterations) +
                        " iterations without meeting the tolerances";
      break;
    }
    if ((point.jac.transpose() * point.r).lpNorm<Eigen::Infinity>() <= options.gradient_tolerance) {
      summary.termination = TerminationType::kGradientTolerance;
      summary.message = "gradient below tolerance";
      break;
    }
    ++summary.iterations;
    factored = Factor(point);
    factored_here = true;
    bool accepted = false;
    for (; lambda < kMaxDamping && !done; lambda *= 10.0) {
      const Eigen::VectorXd step = DampedStep(factored, lambda);
      if (!step.allFinite()) continue;
      if (StepIsNegligible(step, x, options.parameter_tolerance)) {
        summary.termination = TerminationType::kParameterTolerance;
        summary.message = "parameter step below tolerance";
        done = true;
        break;
      }
      const Eigen::VectorXd candidate = x + step;
      double trial_cost = 0.0;
      if (!EvaluateResiduals(residual, candidate, trial_r, trial_cost) || trial_cost > point.cost) {
        continue;
      }
      Point next;
      if (!EvaluateWithJacobian(residual, candidate, next)) continue;
      const double decrease = point.cost - next.cost;
      x = candidate;
      point = std::move(next);
      factored_here = false;
      lambda = std::max(lambda / 10.0, 1e-12);
      accepted = true;
      if (decrease <= options.function_tolerance * (point.cost + decrease)) {
        summary.termination = TerminationType::kFunctionTolerance;
        summary.message = "relative cost decrease below tolerance";
        done = true;
      }
      break;
    }
    if (!accepted && !done) {
      FinishWithoutStep(point, factored.scale, summary);
      done = true;
    }
  }
  summary.final_cost = point.cost;
  if (solution != nullptr) {
    solution->r_factor = factored_here ? std::move(factored.rfac) : Factor(point).rfac;
    solution->residuals = std::move(point.r);
    solution->jacobian = std::move(point.jac);
  }
  return summary;
}

Eigen::MatrixXd CovarianceFromJacobian(Eigen::Ref<const Eigen::MatrixXd> jacobian,
                                       Eigen::Ref<const Eigen::VectorXd> residual) {
  return CovarianceFromFactor(UpperFactor(Eigen::HouseholderQR<Eigen::MatrixXd>(jacobian)),
                              residual);
}

Eigen::MatrixXd CovarianceFromFactor(Eigen::Ref<const Eigen::MatrixXd> r_factor,
                                     Eigen::Ref<const Eigen::VectorXd> residual) {
  const Eigen::Index n = residual.size();
  const Eigen::Index p = r_factor.cols();
  const double dof = static_cast<double>(std::max<Eigen::Index>(n - p, 1));
  const double sigma2 = residual.squaredNorm() / dof;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(r_factor, Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(p, p);
  const double tol = sv.size() > 0 ? sv[0] * 1e-12 * static_cast<double>(std::max(n, p)) : 0.0;
  for (Eigen::Index i = 0; i < sv.size(); ++i) {
    if (sv[i] > tol) {
      cov += svd.matrixV().col(i) * svd.matrixV().col(i).transpose() / (sv[i] * sv[i]);
    } else {
      for (Eigen::Index j = 0; j < p; ++j) {
        if (svd.matrixV()(j, i) != 0.0) cov(j, j) = std::numeric_limits<double>::infinity();
      }
    }
  }
  return sigma2 * cov;
}

}  // namespace vibid::numerics
