#include "vibid/ident/solver.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>

#include "vibid/common/error.hpp"

namespace vibid::ident {

void LmOptions::Validate() const {
  Require(max_iterations > 0, "solver: max_iterations must be > 0");
  Require(function_tolerance >= 0.0 && std::isfinite(function_tolerance), "solver: function_tolerance must be >= 0");
  Require(parameter_tolerance >= 0.0 && std::isfinite(parameter_tolerance), "solver: parameter_tolerance must be >= 0");
  Require(gradient_tolerance >= 0.0 && std::isfinite(gradient_tolerance), "solver: gradient_tolerance must be >= 0");
  Require(initial_damping > 0.0 && std::isfinite(initial_damping), "solver: initial_damping must be > 0");
  Require(jacobian_step > 0.0 && jacobian_step < 0.1, "solver: jacobian_step must be in (0, 0.1)");
}

const char* TerminationName(Termination termination) {
  switch (termination) {
    case Termination::kFunctionTolerance: return "function_tolerance";
    case Termination::kParameterTolerance: return "parameter_tolerance";
    case Termination::kGradientTolerance: return "gradient_tolerance";
    case Termination::kMaxIterations: return "max_iterations";
    case Termination::kNumericalFailure: return "numerical_failure";
  }
  return "unknown";
}

bool SolverSummary::Converged() const {
  return termination == Termination::kFunctionTolerance || termination == Termination::kParameterTolerance ||
         termination == Termination::kGradientTolerance;
}

namespace {

bool Evaluate(const ResidualFunction& f, const Eigen::VectorXd& p, Eigen::VectorXd& r, double& cost) {
  if (!f(p, r)) return false;
  if (!r.allFinite()) return false;
  cost = 0.5 * r.squaredNorm();
  return true;
}

// Central differences: the fits here are judged at the 1e-4 level, where forward differences'
// O(h) error on ill-scaled residuals would show.
bool Jacobian(const ResidualFunction& f, const Eigen::VectorXd& p, Eigen::Index m, double rel_step,
              Eigen::MatrixXd& jac) {
  jac.resize(m, p.size());
  Eigen::VectorXd q = p;
  Eigen::VectorXd rp(m);
  Eigen::VectorXd rm(m);
  for (Eigen::Index j = 0; j < p.size(); ++j) {
    const double h = rel_step * std::max(std::abs(p[j]), 1.0);
    q[j] = p[j] + h;
    if (!f(q, rp) || !rp.allFinite()) return false;
    q[j] = p[j] - h;
    if (!f(q, rm) || !rm.allFinite()) return false;
    q[j] = p[j];
    jac.col(j) = (rp - rm) / (2.0 * h);
  }
  return true;
}

}  // namespace

SolverSummary LevenbergMarquardt(const ResidualFunction& residual, Eigen::VectorXd& params,
                                 const LmOptions& options) {
  options.Validate();
  SolverSummary summary;
  Eigen::VectorXd r;
  double cost = 0.0;
  if (!Evaluate(residual, params, r, cost)) {
    summary.message = "residuals are not finite at the starting point";
    return summary;
  }
  summary.initial_cost = cost;
  summary.final_cost = cost;
  double lambda = options.initial_damping;
  Eigen::MatrixXd jac;
  Eigen::VectorXd trial_r;
  for (int iter = 0; iter < options.max_iterations; ++iter) {
    summary.iterations = iter + 1;
    if (!Jacobian(residual, params, r.size(), options.jacobian_step, jac)) {
      summary.termination = Termination::kNumericalFailure;
      summary.message = "Jacobian is not finite";
      return summary;
    }
    const Eigen::VectorXd g = jac.transpose() * r;
    if (g.lpNorm<Eigen::Infinity>() <= options.gradient_tolerance) {
      summary.termination = Termination::kGradientTolerance;
      summary.message = "gradient below tolerance";
      return summary;
    }
    const Eigen::MatrixXd jtj = jac.transpose() * jac;
    Eigen::VectorXd diag = jtj.diagonal().cwiseMax(1e-12 * std::max(jtj.diagonal().maxCoeff(), 1e-300));
    bool accepted = false;
    // Raise the damping until a step lowers the cost; give up after the damping has made the
    // step negligible.
    for (int tries = 0; tries < 40 && !accepted; ++tries) {
      Eigen::MatrixXd a = jtj;
      a.diagonal() += lambda * diag;
      const Eigen::VectorXd step = a.ldlt().solve(-g);
      if (!step.allFinite()) {
        lambda *= 10.0;
        continue;
      }
      const Eigen::VectorXd trial = params + step;
      double trial_cost = 0.0;
      if (Evaluate(residual, trial, trial_r, trial_cost) && trial_cost < cost) {
        const double decrease = (cost - trial_cost) / std::max(cost, 1e-300);
        const double step_norm = step.norm();
        params = trial;
        r = trial_r;
        cost = trial_cost;
        summary.final_cost = cost;
        lambda = std::max(lambda / 3.0, 1e-12);
        accepted = true;
        if (decrease <= options.function_tolerance) {
          summary.termination = Termination::kFunctionTolerance;
          summary.message = "relative cost decrease below tolerance";
          return summary;
        }
        if (step_norm <= options.parameter_tolerance * (params.norm() + options.parameter_tolerance)) {
          summary.termination = Termination::kParameterTolerance;
          summary.message = "step below tolerance";
          return summary;
        }
      } else {
        const double step_norm = step.norm();
        if (step_norm <= options.parameter_tolerance * (params.norm() + options.parameter_tolerance)) {
          // Even the tiny steps do not help: we sit at the minimum within the working precision.
          summary.termination = Termination::kParameterTolerance;
          summary.message = "no smaller cost within the step tolerance";
          return summary;
        }
        lambda *= 4.0;
      }
    }
    if (!accepted) {
      summary.termination = Termination::kNumericalFailure;
      summary.message = "no step reduces the cost";
      return summary;
    }
  }
  summary.termination = Termination::kMaxIterations;
  std::ostringstream msg;
  msg << "stopped after " << options.max_iterations << " iterations";
  summary.message = msg.str();
  return summary;
}

}  // namespace vibid::ident
